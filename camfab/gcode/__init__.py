"""camfab.gcode — see the issue tracker for its planned contents."""
