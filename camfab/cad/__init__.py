"""CAD exports: plate geometry (bulge loops), STL (trimesh), STEP (cadquery, imported lazily)."""
