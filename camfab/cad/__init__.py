"""camfab.cad — see the issue tracker for its planned contents."""
