"""Generate ``camfab/cad/dxf_skeleton.py``: the constant parts of ezdxf's plate DXF, as data.

    python tools/dxf_skeleton.py            # (re)write the module
    python tools/dxf_skeleton.py --check    # exit 1 when the module differs from what ezdxf makes now

:mod:`camfab.cad.dxfwrite` writes the plate DXF without ezdxf.  Everything in that file but the custom header
properties, the ``PLATE`` layer, the entities and the handles allocated after them is what ezdxf writes for
``ezdxf.new("R2010"/"R12", setup=False)`` with camfab's header units and its nine layers
(:func:`camfab.cad.dxf.build_document`), written in fixed-metadata mode with CLASSES sorted
(:func:`camfab.cad.dxf.write_deterministic`).  This script writes exactly that document with ezdxf and cuts the
text into pieces around the places that vary:

* ``"custom"``: after ``$LASTSAVEDBY`` (where ezdxf writes the custom properties; R2010 only, an R12 header
  has neither);
* ``"layer_count"``: the LAYER table's entry count (``70``);
* ``"extra_layers"``: before the LAYER table's ``ENDTAB`` (where a groove cam's ``PLATE`` layer or a developed
  cylinder's ``OUTLINE`` goes; their entries are ``EXTRA_LAYERS``, split around the handle);
* ``"entities"``: the ENTITIES section's content;
* an int: a handle ezdxf allocates while writing (APPIDs, metadata, ``$HANDSEED``), at or after the first free
  handle; in a file with ``n`` layers and entities more it is ``n`` higher.

Each skeleton is ``(texts, slots)`` with ``len(texts) == len(slots) + 1``.
"""
from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import ezdxf  # noqa: E402

from camfab.cad.dxf import LAYERS, write_deterministic  # noqa: E402

OUT = ROOT / "camfab" / "cad" / "dxf_skeleton.py"
logging.getLogger("ezdxf").setLevel(logging.ERROR)  # not its R12 note that R12 files have no $INSUNITS
#: group codes whose values are handles (DXF reference: 5, 105, 320-369, 390-399, 480-481, 1005)
HANDLE_CODES = frozenset([5, 105, 1005, *range(320, 370), *range(390, 400), 480, 481])


def base_document(version: str):
    """The document :func:`camfab.cad.dxf.build_document` makes before custom properties and entities."""
    doc = ezdxf.new(version, setup=False)
    if version != "R12":
        doc.header["$INSUNITS"] = 4
        doc.header["$MEASUREMENT"] = 1
    for name, colour in LAYERS.items():
        doc.layers.add(name, color=colour)
    return doc


def _pairs(text: str) -> list[tuple[str, str]]:
    lines = text.split("\n")
    assert lines[-1] == "" and len(lines) % 2 == 1, "a DXF text is pairs of lines"
    return list(zip(lines[0:-1:2], lines[1:-1:2], strict=True))


def skeleton(version: str) -> tuple[tuple[str, ...], tuple[int | str, ...], int, str, int]:
    """``(texts, slots, first_free_handle, model_space_owner, layer_count)`` of ``version``'s skeleton (module
    notes)."""
    doc = base_document(version)
    first = int(str(doc.entitydb.handles), 16)
    owner = doc.modelspace().block_record_handle
    texts: list[str] = []
    slots: list[int | str] = []
    cur: list[str] = []

    def cut(slot: int | str) -> None:
        texts.append("".join(cur))
        cur.clear()
        slots.append(slot)

    pairs = _pairs(write_deterministic(doc))
    table = section = None
    count = 0
    for i, (code, value) in enumerate(pairs):
        c = int(code)
        prev = pairs[i - 1] if i else ("", "")
        if c == 0 and value == "ENDTAB" and table == "LAYER":
            cut("extra_layers")
        if c == 2 and prev == ("  0", "TABLE"):
            table = value
            counted = False
        if c == 2 and prev == ("  0", "SECTION"):
            section = value
        if c == 70 and table == "LAYER" and not counted and section == "TABLES":
            counted = True
            count = int(value)
            cur.append(f"{code}\n")
            cut("layer_count")
            cur.append("\n")
            continue
        if c in HANDLE_CODES and _late(value, first):
            cur.append(f"{code}\n")
            cut(int(value, 16))
            cur.append("\n")
            continue
        cur.append(f"{code}\n{value}\n")
        if prev == ("  9", "$LASTSAVEDBY"):
            cut("custom")
        if c == 2 and value == "ENTITIES" and prev == ("  0", "SECTION"):
            cut("entities")
        if c == 0 and value == "ENDTAB":
            table = None
    texts.append("".join(cur))
    named = ["layer_count", "extra_layers", "entities"]
    named = named if version == "R12" else ["custom", *named]
    assert [s for s in slots if isinstance(s, str)] == named, slots
    return tuple(texts), tuple(slots), first, owner, count


def _late(value: str, first: int) -> bool:
    try:
        return int(value, 16) >= first
    except ValueError:
        return False


#: the layers a file may have after the nine (name: ACI colour): a groove plate's rim, a developed cylinder's outline
EXTRA_LAYERS = {"PLATE": 7, "OUTLINE": 8}


def extra_layer(version: str, name: str) -> tuple[str, str]:
    """The entry of layer ``name`` (:data:`EXTRA_LAYERS`) added after the nine, as ezdxf writes it, split around
    its handle."""
    doc = base_document(version)
    handle = doc.layers.add(name, color=EXTRA_LAYERS[name]).dxf.handle
    text = write_deterministic(doc)
    start = text.index(f"  0\nLAYER\n  5\n{handle}\n")
    entry = text[start:text.index("  0\nENDTAB\n", start)]
    before, after = entry.split(f"  5\n{handle}\n")
    return before + "  5\n", "\n" + after


def _literal(text: str, width: int = 110, indent: str = "    ") -> str:
    """``text`` as one tuple item of adjacent string literals, each line of the module within ``width``."""
    chunks: list[str] = []
    for line in text.splitlines(keepends=True):
        if chunks and len(repr(chunks[-1] + line)) <= width:
            chunks[-1] += line
        else:
            chunks.append(line)
    if not chunks:
        return f"{indent}'',\n"
    return f"{indent}(" + f"\n{indent} ".join(repr(c) for c in chunks) + "),\n"


def module_text() -> str:
    out = [f'"""The constant parts of ezdxf {ezdxf.__version__}\'s plate DXF (R2010 and R12), as data.\n\n'
           "GENERATED by tools/dxf_skeleton.py from ezdxf " + ezdxf.__version__ + ": do not edit; run "
           "``python tools/dxf_skeleton.py`` again\nafter an ezdxf upgrade.  Read by :mod:`camfab.cad.dxfwrite`; "
           'the slots are explained in the script.\n"""\n',
           "from __future__ import annotations\n\n",
           f"EZDXF_VERSION = {ezdxf.__version__!r}\n"]
    for version in ("R2010", "R12"):
        texts, slots, first, owner, count = skeleton(version)
        out.append(f"\n{version}_FIRST_HANDLE = {first:#x}\n")
        out.append(f"{version}_OWNER = {owner!r}\n")
        out.append(f"{version}_LAYER_COUNT = {count}\n")
        out.append(f"{version}_EXTRA_LAYERS = {{\n" + "".join(
            f"    {name!r}: (\n{_literal(before, indent=' ' * 8)}{_literal(after, indent=' ' * 8)}    ),\n"
            for name, (before, after) in ((n, extra_layer(version, n)) for n in EXTRA_LAYERS)) + "}\n")
        out.append(f"{version}_SLOTS: tuple[int | str, ...] = {slots!r}\n")
        out.append(f"{version}_TEXTS = (\n" + "".join(_literal(t) for t in texts) + ")\n")
    return "".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="exit 1 when the module is not what ezdxf makes now")
    args = ap.parse_args(argv)
    text = module_text()
    if args.check:
        same = OUT.exists() and OUT.read_text(encoding="utf-8") == text
        print(f"{OUT.relative_to(ROOT)}: {'up to date' if same else 'DIFFERS from ezdxf ' + ezdxf.__version__}")
        return 0 if same else 1
    OUT.write_text(text, encoding="utf-8")
    print(f"wrote {OUT.relative_to(ROOT)} (ezdxf {ezdxf.__version__})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
