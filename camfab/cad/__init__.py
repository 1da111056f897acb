"""CAD exports: plate geometry (bulge loops), STL (numpy and earcut), STEP (cadquery, imported lazily)."""
