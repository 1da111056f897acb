"""Controller post-processors over the common toolpath model (see :mod:`camfab.gcode.post`)."""
from camfab.gcode.posts.base import Post
from camfab.gcode.posts.fanuc import FanucPost
from camfab.gcode.posts.grbl import GrblPost
from camfab.gcode.posts.linuxcnc import LinuxCNCPost

__all__ = ["Post", "LinuxCNCPost", "FanucPost", "GrblPost"]
