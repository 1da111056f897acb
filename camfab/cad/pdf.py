"""Drawing sheets as PDF: one page per sheet at true paper size, and a package's drawing set.

A sheet (:mod:`camfab.cad.drawing`) is drawn in paper millimetres in model space, origin at the sheet's
lower-left corner.  :func:`sheet_pdf` renders it with ezdxf's drawing add-on through its matplotlib back end
onto a page exactly the paper's size (A4 297 × 210 mm, A3 420 × 297 mm): one drawing unit is one millimetre on
the page, so the sheet prints at its own scale (1:1 on the printer).  Lines are black on white at their DXF
lineweights (ISO 128: 0.5 mm outlines, 0.18 mm thin lines).

Text stays text: ezdxf lays out every TEXT, MTEXT line and dimension text (position, rotation, cap height);
each is then written as a PDF text object in the same TrueType font ezdxf measured it with, so a reader can
search and copy it and ``pdftotext`` reads it.  Text in a font that is not TrueType (a stroke font) is drawn
as ezdxf draws it, as outlines, with the same text laid over it invisibly.

Deterministic: matplotlib's own defaults (not the user's ``matplotlibrc``), no creation date, fixed metadata,
so the same sheet gives the same bytes on every run.

:func:`write_drawing_set` streams a package's drawing set into one file: contents page(s) listing every cam
(its verdict, drawing number and page; for a cam without a sheet, why) and then each sheet, one page at a
time (bounded memory: one page is held at once).
"""
from __future__ import annotations

import contextlib
import io
import math
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from ..errors import ExportError, MissingDependencyError
from ..io import atomic_stream
from ..records import dataclass
from ..textsafe import excerpt, plain

__all__ = ["sheet_pdf", "sheet_figure", "paper_size", "read_sheet", "SetEntry", "write_drawing_set",
           "contents_layout", "PT_PER_MM", "CONTENTS_ROWS"]

PT_PER_MM = 72.0 / 25.4
#: the contents page: A4 portrait (mm)
CONTENTS_PAPER = (210.0, 297.0)
#: cams per contents page (a row of 9 mm: the line, and the reason of a cam without a sheet under it)
CONTENTS_ROWS = 25


def _require() -> None:
    try:
        import ezdxf.addons.drawing  # noqa: F401
        import matplotlib  # noqa: F401
    except ImportError as exc:  # pragma: no cover
        raise MissingDependencyError("PDF drawings need ezdxf and matplotlib: pip install ezdxf matplotlib") \
            from exc


def read_sheet(dxf: str | bytes | Path) -> Any:
    """An ezdxf document from a sheet's DXF text (str or bytes) or file."""
    import ezdxf

    if isinstance(dxf, Path):
        return ezdxf.readfile(dxf)
    text = dxf.decode("utf-8") if isinstance(dxf, bytes) else dxf
    return ezdxf.read(io.StringIO(text))


def paper_size(doc: Any) -> tuple[float, float]:
    """The sheet's paper (width, height) in mm: the paper the sheet names (``CAMFAB_PAPER``) in the
    title-block template, else the drawing limits ``$LIMMIN``/``$LIMMAX``.

    Raises ExportError for a document that gives neither."""
    from .sheet import load_template

    name = doc.header.custom_vars.get("CAMFAB_PAPER")
    papers = load_template().get("paper", {})
    if name in papers:
        return float(papers[name]["width_mm"]), float(papers[name]["height_mm"])
    lo, hi = doc.header.get("$LIMMIN"), doc.header.get("$LIMMAX")
    if lo is not None and hi is not None and hi[0] > lo[0] and hi[1] > lo[1]:
        return float(hi[0] - lo[0]), float(hi[1] - lo[1])
    raise ExportError("the drawing names no paper (CAMFAB_PAPER) and has no drawing limits: no page size")


# ---------------------------------------------------------------------------
# rendering
@contextlib.contextmanager
def _mpl_defaults() -> Iterator[None]:
    """matplotlib's defaults whatever the user's matplotlibrc says, TrueType fonts embedded (searchable text),
    no nondeterministic hash salt; nothing global is changed."""
    import matplotlib

    with matplotlib.rc_context():
        matplotlib.rcdefaults()
        matplotlib.rcParams.update({"pdf.fonttype": 42, "svg.hashsalt": "camfab", "path.simplify": False})
        yield


def _font_file(face: Any) -> tuple[str, float] | None:
    """The TrueType file of an ezdxf font face and its em size per cap height (ezdxf scales a text so that the
    height of "A" is the cap height), or None for a font that is not TrueType."""
    from ezdxf.fonts import fonts
    from ezdxf.fonts.ttfonts import TTFontRenderer

    if face is None or not str(face.filename).lower().endswith((".ttf", ".otf", ".ttc")):
        return None
    try:
        ttf = fonts.font_manager.ttf_font_from_font_face(face)
        path = getattr(getattr(ttf.reader, "file", None), "name", None)
        cap = TTFontRenderer(ttf).font_measurements.cap_height
        em = float(ttf["head"].unitsPerEm)
    except Exception:  # noqa: BLE001 - any font the renderer cannot measure is drawn as ezdxf draws it
        return None
    if not path or not Path(path).is_file() or cap <= 0:
        return None
    return str(path), em / cap


def _pipeline_class() -> type:
    """ezdxf's 2D render pipeline, its text written as matplotlib text (see the module docstring)."""
    from ezdxf.addons.drawing.pipeline import RenderPipeline2d, prepare_string_for_rendering

    class TextPipeline(RenderPipeline2d):
        def __init__(self, backend: Any, ax: Any):
            super().__init__(backend)
            self.ax = ax
            self.fonts: dict[str, tuple[str, float] | None] = {}

        def draw_text(self, text: str, transform: Any, properties: Any, cap_height: float,
                      dxftype: str = "TEXT") -> None:
            if not text.strip():
                return
            face = properties.font if properties.font is not None else self.default_font_face
            key = str(getattr(face, "filename", ""))
            if key not in self.fonts:
                self.fonts[key] = _font_file(face)
            font = self.fonts[key]
            ux, uy = transform.transform_direction((1, 0, 0)), transform.transform_direction((0, 1, 0))
            sx, sy = math.hypot(ux.x, ux.y), math.hypot(uy.x, uy.y)
            upright = abs(ux.x * uy.x + ux.y * uy.y) < 1e-9 * sx * sy and ux.x * uy.y - ux.y * uy.x > 0
            real = font is not None and upright and math.isclose(sx, sy, rel_tol=1e-9)
            if not real:  # a stroke font, a width factor or a mirror: ezdxf's outlines, invisible text over them
                super().draw_text(text, transform, properties, cap_height, dxftype)
            at = transform.transform((0, 0, 0))
            colour = self.get_backend_properties(properties).color
            self._text(prepare_string_for_rendering(text, dxftype), at, math.degrees(math.atan2(ux.y, ux.x)),
                       cap_height * sy, font, colour if real else None)

        def _text(self, text: str, at: Any, angle: float, cap_height: float, font: tuple[str, float] | None,
                  colour: str | None) -> None:
            from matplotlib.font_manager import FontProperties

            em_mm = cap_height * (font[1] if font else 1.37)
            prop = FontProperties(fname=font[0]) if font else FontProperties(family="DejaVu Sans")
            self.ax.text(at.x, at.y, text, fontproperties=prop, fontsize=em_mm * PT_PER_MM, rotation=angle,
                         rotation_mode="anchor", ha="left", va="baseline", parse_math=False, usetex=False,
                         color=colour or "black", alpha=None if colour else 0.0, clip_on=False)

    return TextPipeline


def _backend_class() -> type:
    """ezdxf's matplotlib back end without autoscaling (the page is fixed): adding a patch does not update the
    axes' data limits, which is most of matplotlib's time on a sheet of text."""
    from ezdxf.addons.drawing.backend import Backend
    from ezdxf.addons.drawing.matplotlib import MatplotlibBackend
    from ezdxf.npshapes import to_matplotlib_path
    from matplotlib.patches import PathPatch

    class SheetBackend(MatplotlibBackend):
        def _patch(self, paths: Any, properties: Any, filled: bool) -> None:
            try:
                patch = PathPatch(to_matplotlib_path(paths, detect_holes=filled), color=properties.color,
                                  linewidth=0 if filled else self.get_lineweight(properties), fill=filled,
                                  zorder=self._get_z())
            except ValueError:  # matplotlib refuses a degenerate path: nothing to draw
                return
            self.ax.add_artist(patch)

        def draw_path(self, path: Any, properties: Any) -> None:
            self._patch([path], properties, False)

        def draw_filled_paths(self, paths: Any, properties: Any) -> None:
            self._patch(list(paths), properties, True)

        def finalize(self) -> None:
            Backend.finalize(self)

    return SheetBackend


def sheet_figure(doc: Any, size_mm: tuple[float, float] | None = None) -> Any:
    """A matplotlib figure of the sheet's model space on a page of ``size_mm`` (default :func:`paper_size`),
    one drawing unit = 1 mm, black lines at their lineweights on white.  Call inside :func:`_mpl_defaults`."""
    from ezdxf.addons.drawing.config import BackgroundPolicy, ColorPolicy, Configuration, LineweightPolicy
    from ezdxf.addons.drawing.frontend import UniversalFrontend
    from ezdxf.addons.drawing.properties import RenderContext
    from matplotlib.figure import Figure

    w, h = size_mm or paper_size(doc)
    fig = Figure(figsize=(w / 25.4, h / 25.4), dpi=72)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    backend = _backend_class()(ax, adjust_figure=False)
    cfg = Configuration(color_policy=ColorPolicy.BLACK, background_policy=BackgroundPolicy.WHITE,
                        lineweight_policy=LineweightPolicy.ABSOLUTE, lineweight_scaling=PT_PER_MM,
                        min_lineweight=0.13 * PT_PER_MM)
    pipeline = _pipeline_class()(backend, ax)
    UniversalFrontend(RenderContext(doc), pipeline, cfg).draw_layout(doc.modelspace(), finalize=True)
    ax.set_xlim(0.0, w)
    ax.set_ylim(0.0, h)
    ax.set_aspect("auto")
    ax.set_facecolor("white")
    fig.patch.set_facecolor("white")
    return fig


def _metadata(title: str) -> dict[str, Any]:
    from ..version import __version__

    return {"Title": plain(title), "Creator": f"camfab {__version__}", "CreationDate": None}


def sheet_pdf(dxf: str | bytes | Path | Any, *, title: str | None = None) -> bytes:
    """One PDF page of a drawing sheet (its DXF text, file or ezdxf document) at the paper's size.

    The PDF's title is ``title`` or the sheet's design name (``CAMFAB_NAME``).  Same sheet, same bytes."""
    _require()
    from matplotlib.backends.backend_pdf import PdfPages

    doc: Any = dxf if hasattr(dxf, "modelspace") else read_sheet(dxf)
    name = title if title is not None else doc.header.custom_vars.get("CAMFAB_NAME") or "drawing"
    buf = io.BytesIO()
    with _mpl_defaults(), PdfPages(buf, metadata=_metadata(name)) as pdf:
        pdf.savefig(sheet_figure(doc))
    return buf.getvalue()


# ---------------------------------------------------------------------------
# a package's drawing set
@dataclass(frozen=True)
class SetEntry:
    """One cam of a drawing set: its name, verdict, drawing number, and its sheet (the DXF file) or, when it
    has none, why (``reason``)."""

    name: str
    verdict: str | None
    number: str | None = None
    sheet: Path | None = None
    reason: str = ""


def contents_layout(entries: Sequence[SetEntry]) -> tuple[int, list[int | None]]:
    """The number of contents pages and each entry's page in the set (None: no sheet)."""
    n_contents = max(1, math.ceil(len(entries) / CONTENTS_ROWS))
    pages: list[int | None] = []
    nxt = n_contents + 1
    for e in entries:
        pages.append(nxt if e.sheet is not None else None)
        nxt += e.sheet is not None
    return n_contents, pages


def _contents_pages(entries: Sequence[SetEntry], pages: Sequence[int | None], n_contents: int,
                    title: str) -> Iterator[Any]:
    """The contents page figures (A4 portrait): No., cam, drawing number, verdict, page; a cam without a
    sheet shows why instead of a page."""
    from matplotlib.figure import Figure

    w, h = CONTENTS_PAPER
    cols = (15.0, 23.0, 95.0, 140.0, 185.0)  # No. | cam | drawing no. | verdict | page (right-aligned)
    for k in range(n_contents):
        fig = Figure(figsize=(w / 25.4, h / 25.4), dpi=72)
        fig.patch.set_facecolor("white")
        ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
        ax.set_xlim(0.0, w)
        ax.set_ylim(0.0, h)
        ax.set_axis_off()

        def put(x: float, y: float, s: str, size: float = 9.0, ax: Any = ax, **kw: Any) -> None:
            ax.text(x, y, s, fontsize=size, parse_math=False, usetex=False, va="baseline", **kw)

        put(cols[0], h - 20.0, title, 14.0, weight="bold")
        put(cols[0], h - 27.0, f"Contents — {len(entries)} cam(s); page {k + 1} of {n_contents}", 9.0)
        y = h - 40.0
        for x, head in zip(cols[:4], ("No.", "Cam", "Drawing no.", "Verdict"), strict=True):
            put(x, y, head, 9.0, weight="bold")
        put(cols[4], y, "Page", 9.0, weight="bold", ha="right")
        ax.plot([cols[0], cols[4]], [y - 2.0, y - 2.0], color="black", linewidth=0.5)
        y -= 7.0
        for i in range(k * CONTENTS_ROWS, min(len(entries), (k + 1) * CONTENTS_ROWS)):
            e, page = entries[i], pages[i]
            put(cols[0], y, f"{i + 1}.")
            put(cols[1], y, excerpt(plain(e.name), 34))
            put(cols[2], y, excerpt(plain(e.number or "—"), 24))
            put(cols[3], y, (e.verdict or "error").replace("_", " "))
            put(cols[4], y, str(page) if page is not None else "—", ha="right")
            if page is None and e.reason:
                put(cols[1], y - 3.8, "no sheet: " + excerpt(plain(e.reason), 110), 6.5, color="#444444")
            y -= 9.0
        yield fig


def write_drawing_set(path: str | Path, entries: Sequence[SetEntry], *, title: str = "camfab drawing set") -> int:
    """Write the drawing set to ``path`` atomically: contents page(s), then each entry's sheet in order, one
    page rendered at a time.  Returns the number of pages."""
    _require()
    from matplotlib.backends.backend_pdf import PdfPages

    n_contents, pages = contents_layout(entries)
    count = 0
    with _mpl_defaults(), atomic_stream(path) as fh, PdfPages(fh, metadata=_metadata(title)) as pdf:
        for fig in _contents_pages(entries, pages, n_contents, title):
            pdf.savefig(fig)
            count += 1
        for e in entries:
            if e.sheet is None:
                continue
            doc = read_sheet(e.sheet)
            pdf.savefig(sheet_figure(doc))
            del doc
            count += 1
    return count

