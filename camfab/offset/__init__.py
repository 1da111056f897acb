"""camfab.offset — see the issue tracker for its planned contents."""
