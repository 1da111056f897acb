"""Text from the design in output files (docs/decisions.md, "Text from the design in output files"):
:mod:`camfab.textsafe` and every writer that puts a name, a material or a message into DXF, xlsx, G-code,
STEP, SVG/HTML, a package manifest or index; formulas in design workbooks; where a knot file may be."""
from __future__ import annotations

import dataclasses
import html
import io
import json
import re
import zipfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import camfab
from camfab.cad.dxf import DxfContent
from camfab.cad.dxf import dumps as dxf_dumps
from camfab.cad.plate import PlateSpec, circle_loop
from camfab.cli import main
from camfab.errors import SpecError
from camfab.formats import design_to_xlsx, load_design, load_design_xlsx, load_motion_table, read_knots_xlsx
from camfab.io import safe_stem
from camfab.textsafe import (
    DXF_MAX,
    bounded,
    dxf_mtext,
    dxf_string,
    dxf_text,
    gcode_comment,
    mpl_text,
    plain,
    step_string,
)
from tests.conftest import EXAMPLES
from tests.design.test_xlsx_design import E9_MOTION, E9_ROWS

ezdxf = pytest.importorskip("ezdxf")
openpyxl = pytest.importorskip("openpyxl")

#: a newline and DXF group codes that, written raw, end the header and add a LINE on layer EVIL (ezdxf's
#: recover mode read it)
INJECT = ("x\n  0\nENDSEC\n  0\nSECTION\n  2\nENTITIES\n  0\nLINE\n  8\nEVIL\n 10\n0\n 20\n0\n 11\n100\n 21\n100\n"
          "  0\nENDSEC")
#: one name with every hazard: a formula start, ESC, G-code comment breakers, DXF/MTEXT codes, DXF injection
HOSTILE = '=HYPERLINK("http://x")\x1b(;%)^J{\\P}%%d\\U+0041 ' + INJECT


# --- the functions ---------------------------------------------------------------------------------------
@pytest.mark.parametrize(("text", "want"), [
    ("Ejemplo9RT", "Ejemplo9RT"),
    ("a\nb\r\nc\td\x00e\x1bf\x7fg\x85h\u2028i\u2029j", "a b  c d e f g h i j"),
    ("Leva ñ 日本", "Leva ñ 日本"),
    ("\ud800x", "\ufffdx"),
])
def test_plain(text, want):
    assert plain(text) == want


def test_dxf_escapes():
    assert dxf_string("a^Jb\nc") == "a^ Jb c"
    assert dxf_text("100% %%d \\U+0041 \\x") == "100%%% %%%%%%d \\U+005CU+0041 \\x"
    assert dxf_mtext("a{b}\\Pc%^") == "a\\{b\\}\\\\Pc%%%^ "
    long = dxf_text("%" * 3000)
    assert len(long) <= DXF_MAX and long.endswith("…") and set(long[:-1]) == {"%"} and (len(long) - 1) % 3 == 0


def test_gcode_step_mpl_bounded():
    assert gcode_comment("a(b)c;d%e\nf é") == "a[b]c d e f ?"
    assert len(gcode_comment("x" * 1000)) == 240
    assert step_string("O'Brien \\ ñ😀") == "O''Brien \\\\ \\X2\\00F1D83DDE00\\X0\\"
    assert mpl_text("a $x$") == r"a \$x\$"
    msg = bounded("<script>" + "y" * 10_000 + "\x1b\n" + "\n".join(f"line {i}" for i in range(30)))
    lines = msg.split("\n")
    assert len(lines) == 11 and all(len(ln) <= 300 for ln in lines) and lines[0].endswith("…")
    assert "\x1b" not in msg and lines[-1] == "… (21 more lines)"


def _step_decode(s: str) -> str:
    """Inverse of step_string (the ISO 10303-21 string rules)."""
    def wide(m):
        return bytes.fromhex(m.group(1)).decode("utf-16-be", "surrogatepass")
    return re.sub(r"\\X2\\([0-9A-F]*)\\X0\\", wide, s).replace("''", "'").replace("\\\\", "\\")


@settings(max_examples=300, deadline=None)
@given(st.text())
def test_any_text_stays_one_line_and_round_trips(text):
    p = plain(text)
    assert not any(c in p for c in "\n\r\x00\x1b\x85\u2028\u2029")
    for f in (dxf_string, dxf_text, dxf_mtext, gcode_comment, mpl_text):
        assert "\n" not in f(text) and "\r" not in f(text)
    s = step_string(text)
    assert all(32 <= ord(c) < 127 for c in s) and "'" not in s.replace("''", "")
    assert _step_decode(s) == p
    shown, want = _shown(dxf_text(text[:250])), p[:250]
    assert shown == want or (want.endswith("^") and shown == want[:-1])  # ezdxf drops a final caret "^ "


def _shown(text: str) -> str:
    """What a CAD program shows for a TEXT value (ezdxf's reading, plus AutoCAD's ``\\U+005C`` = ``\\``)."""
    return ezdxf.tools.text.plain_text(text).replace("\\U+005C", "\\")


# --- DXF -------------------------------------------------------------------------------------------------
def _read_dxf(data: str):
    from ezdxf import recover

    doc = ezdxf.read(io.StringIO(data))
    auditor = doc.audit()
    assert not auditor.has_errors, [str(e) for e in auditor.errors]
    rdoc, rauditor = recover.read(io.BytesIO(data.encode("utf-8")))  # the tolerant reader (it found the LINE)
    assert not rauditor.has_errors
    for d in (doc, rdoc):
        assert "EVIL" not in d.layers
        assert not [e for e in d.entitydb.values() if e.dxf.hasattr("layer") and e.dxf.layer == "EVIL"]
    return doc


def test_profile_dxf_name_cannot_inject_entities():
    content = DxfContent(profiles=(circle_loop(30.0),), name=INJECT)
    for flavour in ("lwpolyline", "r12", "spline"):
        doc = _read_dxf(dxf_dumps(content, flavour=flavour))
        assert {e.dxftype() for e in doc.modelspace()} <= {"LWPOLYLINE", "SPLINE", "LINE", "ARC", "CIRCLE"}
        if flavour != "r12":
            assert doc.header.custom_vars.get("CAMFAB_NAME") == plain(INJECT)


@pytest.fixture(scope="module")
def hostile_run(tmp_path_factory):
    """``camfab run`` of Ejemplo9RT named HOSTILE with material "C45 {\\P}%%d^J", shop outputs only."""
    folder = tmp_path_factory.mktemp("hostile")
    text = (EXAMPLES / "ejemplo9rt.toml").read_text(encoding="utf-8")
    text = text.replace('name = "Ejemplo9RT"', f"name = {json.dumps(HOSTILE)}")
    text = text.replace("[manufacturing]\n", '[manufacturing]\nmaterial = "C45 {\\\\P}%%d^J\\n0\\nLINE"\n')
    d = folder / "d.toml"
    d.write_text(text, encoding="utf-8")
    out = folder / "out"
    assert main(["run", str(d), "-o", str(out), "--outputs", "dxf,drawing,xlsx,gcode"]) == 0
    return out, safe_stem(HOSTILE)


def test_drawing_name_and_material_are_text(hostile_run):
    out, stem = hostile_run
    for f in (f"{stem}.dxf", f"{stem}_drawing.dxf"):
        doc = _read_dxf((out / f).read_text(encoding="utf-8"))
        assert doc.header.custom_vars.get("CAMFAB_NAME") == dxf_string(HOSTILE)
    doc = ezdxf.readfile(out / f"{stem}_drawing.dxf")
    texts = [_shown(t.dxf.text) for t in doc.modelspace().query("TEXT")]
    assert plain(HOSTILE) in texts  # the title block shows the whole name, codes as typed
    notes = doc.modelspace().query("MTEXT")[0].plain_text()
    assert any(ln.endswith("Material: C45 {\\P}%%d^J 0 LINE.") for ln in notes.split("\n"))  # literally


def test_run_program_with_a_hostile_name(hostile_run):
    from camfab.gcode import parse

    out, stem = hostile_run
    text = (out / f"{stem}.nc").read_text(encoding="ascii")
    assert parse(text).moves and text.count("%") == 0
    head = [ln for ln in text.splitlines() if ln.startswith("(design: ")]
    assert head == [f"({gcode_comment('design: ' + HOSTILE)})"] and all(len(ln) <= 255 for ln in text.splitlines())


# --- xlsx ------------------------------------------------------------------------------------------------
def _no_formulas(wb) -> None:
    for ws in wb.worksheets:
        for row in ws.iter_rows():
            assert all(c.data_type != "f" for c in row), ws.title


def test_workbook_name_is_a_string_never_a_formula(hostile_run):
    out, stem = hostile_run
    wb = openpyxl.load_workbook(out / f"{stem}.xlsx")  # a valid workbook (ESC replaced, not a crash)
    _no_formulas(wb)
    a2 = wb["CAM-DAS"]["A2"]
    assert a2.data_type == "s" and a2.value == plain(HOSTILE) and a2.quotePrefix
    assert wb.properties.title == plain(HOSTILE)


@pytest.mark.parametrize("name", ['=HYPERLINK("http://x")', "\x1bname", "+1", "@SUM(A1)", "-2+3"])
def test_design_workbook_keeps_the_name_as_text(tmp_path, name):
    spec = load_design(EXAMPLES / "ejemplo9rt.toml")
    spec = dataclasses.replace(spec, name=name, description="=1+1\x1b")
    data = design_to_xlsx(spec)
    wb = openpyxl.load_workbook(io.BytesIO(data))
    _no_formulas(wb)
    cell = wb["design"]["B2"]
    assert cell.data_type == "s" and cell.value == plain(name)
    (tmp_path / "d.xlsx").write_bytes(data)
    back = load_design_xlsx(tmp_path / "d.xlsx")  # text cells, not formulas: read back as typed
    assert back.name == plain(name).strip() and back.description == "=1+1"  # the reader strips cells


# --- G-code ----------------------------------------------------------------------------------------------
COMMENT = re.compile(r"\(([^()]*)\)")


@pytest.mark.parametrize("post", ["linuxcnc", "fanuc", "grbl"])
def test_gcode_comments_cannot_be_broken_out_of(post):
    from camfab.gcode import Job, Segment, contour_toolpath, dumps, parse

    circle = [Segment((20, 0), (20, 0), center=(0, 0))]

    def program(name):
        return dumps(contour_toolpath(circle, Job(tool_diameter_mm=6, depth_mm=5, roughing_passes=0,
                                                  design_name=name)), post)

    evil, good = program(HOSTILE + " (MSG, hi) ;M30 %"), program("cam")
    for line in evil.splitlines():
        if line == "%":
            continue
        comments = COMMENT.findall(line)
        code = COMMENT.sub("", line)
        assert not any(c in code for c in "();%"), line
        assert all(not any(c in b for c in ";%") and all(32 <= ord(c) < 127 for c in b) for b in comments), line
        assert len(line) <= 255
    assert evil.count("%") == (2 if post == "fanuc" else 0) == good.count("%")

    def code_only(text):
        return [COMMENT.sub("", ln).strip() for ln in text.splitlines() if COMMENT.sub("", ln).strip()]
    assert code_only(evil) == code_only(good)
    assert [m.end for m in parse(evil).moves] == [m.end for m in parse(good).moves]


# --- STEP ------------------------------------------------------------------------------------------------
def test_step_product_name_reads_back(tmp_path):
    pytest.importorskip("cadquery")
    import cadquery as cq
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPCAFControl import STEPCAFControl_Reader
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDF import TDF_LabelSequence
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    from camfab.cad import step

    name = "../../O'Brien \\ x\n#1=FOO(); Leva ñ 日本 😀 " + "y" * 200
    text = step.dumps(circle_loop(30.0), PlateSpec(thickness_mm=5.0), name=name)
    assert all(c == "\n" or 32 <= ord(c) < 127 for c in text)
    p = tmp_path / "p.step"
    p.write_text(text, encoding="ascii")
    assert cq.importers.importStep(str(p)).val().isValid()
    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    assert reader.ReadFile(str(p)) == IFSelect_RetDone and reader.Transfer(doc)
    labels = TDF_LabelSequence()
    XCAFDoc_DocumentTool.ShapeTool_s(doc.Main()).GetFreeShapes(labels)
    attr = TDataStd_Name()
    assert labels.Length() == 1 and labels.Value(1).FindAttribute(TDataStd_Name.GetID_s(), attr)
    assert attr.Get().ToExtString() == plain(name)  # OCC reads the whole name back


@pytest.mark.slow
def test_export_step_of_a_long_hostile_name(tmp_path):
    """A 230-character name with quotes, backslashes and a newline: every file of `export` is written."""
    pytest.importorskip("cadquery")
    name = "X" + ("O'Brien \\ \n" * 21)[:229]  # ends in a backslash (the reader strips white space)
    assert len(name) == 230
    d = tmp_path / "d.toml"
    text = (EXAMPLES / "ejemplo9rt.toml").read_text(encoding="utf-8")
    d.write_text(text.replace('name = "Ejemplo9RT"', f"name = {json.dumps(name)}"), encoding="utf-8")
    out = tmp_path / "out"
    assert main(["export", str(d), "--dxf", "--stl", "--step", "-o", str(out)]) == 0
    stem = safe_stem(name)
    assert sorted(p.name for p in out.iterdir()) == sorted(f"{stem}.{s}" for s in ("dxf", "step", "stl"))
    assert step_string(name) in (out / f"{stem}.step").read_text(encoding="ascii")


# --- SVG / HTML ------------------------------------------------------------------------------------------
def test_report_with_a_hostile_name(tmp_path):
    pytest.importorskip("matplotlib")
    markupsafe = pytest.importorskip("markupsafe")
    from camfab.report.html import render_report

    name = 'a $\\frac{$ <script>alert("x")</script> & \'q\''
    cam = camfab.Cam(dataclasses.replace(camfab.load("ejemplo9rt").spec, name=name))
    files = render_report(cam.spec, cam.geometry, cam.check())  # the mathtext used to raise here
    page = files["report.html"].decode()
    assert "<script>alert" not in page
    assert str(markupsafe.escape(name)) in page  # shown whole, escaped
    svgs = [v.decode() for k, v in files.items() if k.endswith(".svg")]
    assert svgs and all("<script>alert" not in s for s in svgs)
    assert any("&lt;script&gt;alert" in s and "frac{$" in s for s in svgs)  # the title, literally


# --- design workbooks: formulas and external links -------------------------------------------------------
def _book(path: Path, edit=None, design_title="design") -> Path:
    wb = openpyxl.Workbook()
    ws = wb.active
    ws.title = design_title
    for r in E9_ROWS:
        ws.append(list(r))
    ms = wb.create_sheet("motion")
    for r in E9_MOTION:
        ms.append(list(r))
    if edit is not None:
        edit(wb)
    wb.save(path)
    return path


def _with_cached_value(path: Path, sheet: int, formula: str, value: str) -> None:
    """Store ``value`` as the cached result of ``formula`` (what Excel saves, openpyxl does not)."""
    src = zipfile.ZipFile(path)
    entries = {i.filename: src.read(i.filename) for i in src.infolist()}
    src.close()
    name = f"xl/worksheets/sheet{sheet}.xml"
    f = html.escape(formula[1:], quote=False).encode()
    assert b"<f>" + f + b"</f>" in entries[name]
    entries[name] = entries[name].replace(b"<f>" + f + b"</f><v></v>", b"<f>" + f + b"</f><v>" + value.encode()
                                          + b"</v>").replace(b"<f>" + f + b"</f><v />",
                                                             b"<f>" + f + b"</f><v>" + value.encode() + b"</v>")
    if f"<v>{value}</v>".encode() not in entries[name]:
        entries[name] = entries[name].replace(b"<f>" + f + b"</f>", b"<f>" + f + b"</f><v>" + value.encode()
                                              + b"</v>")
    with zipfile.ZipFile(path, "w") as dst:
        for k, v in entries.items():
            dst.writestr(k, v)


def test_plain_design_workbook_still_loads(tmp_path):
    spec = load_design_xlsx(_book(tmp_path / "d.xlsx", lambda wb: wb["design"].cell(4, 3, "=1+1")))
    assert spec.name == "E9"  # a formula in a notes column is not an input: ignored as before


@pytest.mark.parametrize(("where", "path"), [
    (("design", "B4", "=0.5*2"), "cam.omega_rad_s [design!B4]"),
    (("Design", "B4", "=0.5*2"), "cam.omega_rad_s [Design!B4]"),
    (("design", "A5", '="follower.type"'), "design!A5"),
    (("motion", "B3", "=5+5"), "motion!B3"),
])
def test_formulas_in_a_design_workbook_are_refused(tmp_path, capsys, where, path):
    sheet, cell, formula = where

    def edit(wb):
        wb[sheet][cell] = formula
    p = _book(tmp_path / "d.xlsx", edit, design_title=sheet if sheet != "motion" else "design")
    with pytest.raises(SpecError) as info:
        load_design_xlsx(p)
    (problem,) = info.value.problems
    assert problem.path == path and "formulas are not accepted in a design workbook" in problem.rule
    assert "type the value" in problem.fix
    assert main(["check", str(p)]) == 2
    assert f"{path} = {formula!r}: formulas are not accepted" in capsys.readouterr().err


def test_external_link_is_refused_not_read_through_its_cached_value(tmp_path):
    from openpyxl.packaging.relationship import Relationship
    from openpyxl.workbook.external_link.external import (
        ExternalBook,
        ExternalCell,
        ExternalLink,
        ExternalRow,
        ExternalSheetData,
        ExternalSheetDataSet,
        ExternalSheetNames,
    )

    def edit(wb):
        wb["design"]["B4"] = "=[1]Sheet1!$B$4"
        data = ExternalSheetDataSet(sheetData=[ExternalSheetData(sheetId=0, row=[
            ExternalRow(r=4, cell=[ExternalCell(r="B4", v="2")])])])
        link = ExternalLink(externalBook=ExternalBook(sheetNames=ExternalSheetNames(sheetName=["Sheet1"]),
                                                      sheetDataSet=data, id="rId1"))
        link.file_link = Relationship(type="externalLinkPath", Target="file:///C:/other.xlsx",
                                      TargetMode="External", Id="rId1")
        wb._external_links.append(link)
    p = _book(tmp_path / "d.xlsx", edit)
    _with_cached_value(p, 1, "=[1]Sheet1!$B$4", "2")
    assert openpyxl.load_workbook(p, data_only=True)["design"]["B4"].value == 2  # what was used silently
    with pytest.raises(SpecError) as info:
        load_design_xlsx(p)
    (problem,) = info.value.problems
    assert problem.path == "cam.omega_rad_s [design!B4]" and "reads another workbook" in problem.rule


def test_formula_in_a_knot_workbook_is_refused(tmp_path):
    wb = openpyxl.Workbook()
    ws = wb.active
    for r in (["angle", "s", "v", "a"], [0, 0, 0, 0], [90, "=2+3", 0, 0], [180, 0, 0, 0]):
        ws.append(r)
    wb.save(tmp_path / "k.xlsx")
    with pytest.raises(SpecError, match=r"cells hold formulas: B3; formulas are not accepted"):
        read_knots_xlsx(tmp_path / "k.xlsx")
    ws["B3"] = 5
    wb.save(tmp_path / "k.xlsx")
    assert read_knots_xlsx(tmp_path / "k.xlsx")[1] == [90.0, 5.0, 0.0, 0.0]


# --- knot files outside the design's folder --------------------------------------------------------------
KNOTS = "angle,s,v,a\n0,0,0,0\n90,5,0,0\n180,0,0,0\n"


def _knot_design(folder: Path, file: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    d = folder / "d.toml"
    d.write_text(f'name = "K"\n[cam]\nkind = "disc"\nomega_rad_s = 1.0\n'
                 f'[follower]\ntype = "roller"\nmotion = "translating"\nbase_radius_mm = 35.0\nroller_radius_mm = 7.0\n'
                 f'[motion_table]\nfile = {json.dumps(file)}\ndegree = 5\n', encoding="utf-8")
    return d


@pytest.mark.parametrize("how", ["dotdot", "absolute", "symlink"])
def test_knot_file_outside_the_design_folder_is_refused(tmp_path, capsys, how):
    (tmp_path / "secret.csv").write_text(KNOTS, encoding="utf-8")
    design_dir = tmp_path / "designs"
    design_dir.mkdir()
    file = {"dotdot": "../secret.csv", "absolute": str(tmp_path / "secret.csv"), "symlink": "link.csv"}[how]
    if how == "symlink":
        (design_dir / "link.csv").symlink_to(tmp_path / "secret.csv")
    d = _knot_design(design_dir, file)
    with pytest.raises(SpecError) as info:
        load_design(d)
    (problem,) = info.value.problems
    assert problem.path == "motion_table.file" and "outside the design's folder" in problem.rule
    assert "--allow-outside-files" in problem.fix
    assert main(["check", str(d)]) == 2
    assert "motion_table.file" in capsys.readouterr().err
    assert load_design(d, allow_outside_files=True).motion_table is not None
    assert camfab.load(d, allow_outside_files=True).name == "K"
    assert main(["check", str(d), "--allow-outside-files"]) in (0, 1)


def test_knot_files_inside_the_design_folder_are_read(tmp_path):
    design_dir = tmp_path / "designs"
    (design_dir / "sub").mkdir(parents=True)
    (design_dir / "sub" / "k.csv").write_text(KNOTS, encoding="utf-8")
    for file in ("sub/k.csv", "./sub/../sub/k.csv", str(design_dir / "sub" / "k.csv")):
        assert load_design(_knot_design(design_dir, file)).motion_table is not None


def test_knot_file_of_a_design_without_a_folder_is_read_as_given(tmp_path):
    """A dict (no folder) is read as the program gave it; a base_dir confines it."""
    (tmp_path / "k.csv").write_text(KNOTS, encoding="utf-8")
    table = {"file": str(tmp_path / "k.csv"), "degree": 5}
    assert load_motion_table(table).source == str(tmp_path / "k.csv")
    with pytest.raises(SpecError, match="outside the design's folder"):
        load_motion_table(table, base_dir=tmp_path / "elsewhere")
    assert load_motion_table(table, base_dir=tmp_path / "elsewhere", allow_outside_files=True)


def test_xlsx_design_knot_file_is_confined_too(tmp_path):
    (tmp_path / "k.csv").write_text(KNOTS, encoding="utf-8")
    rows = [r for r in E9_ROWS] + [("motion_table.file", "../k.csv"), ("motion_table.degree", 5)]
    wb = openpyxl.Workbook()
    for r in rows:
        wb.active.append(list(r))
    wb.active.title = "design"
    (tmp_path / "x").mkdir()
    wb.save(tmp_path / "x" / "d.xlsx")
    with pytest.raises(SpecError) as info:
        load_design_xlsx(tmp_path / "x" / "d.xlsx")
    assert any(p.path.startswith("motion_table.file") and "outside" in p.rule for p in info.value.problems)
    assert load_design_xlsx(tmp_path / "x" / "d.xlsx", allow_outside_files=True).motion_table is not None


# --- package: bounded errors, folders that cannot clash --------------------------------------------------
@pytest.mark.parametrize("before", ["", "0,0,0,0\n"])
def test_package_error_message_is_bounded_and_escaped(tmp_path, before):
    """The bad line of a knot file (first or second, 10 000 characters, with <script> and ESC) is quoted
    bounded in the manifest and escaped in the index."""
    src = tmp_path / "src"
    src.mkdir()
    bad = "<script>alert(1)</script>" + "9" * 10_000 + "\x1b"
    (src / "k.csv").write_text(before + bad + "\n", encoding="utf-8")
    _knot_design(src, "k.csv")
    out = tmp_path / "out"
    assert main(["package", str(src), "-o", str(out), "--outputs", "lift_table"]) == 2
    (entry,) = json.loads((out / "manifest.json").read_text())["cams"]
    err = entry["error"]
    assert entry["status"] == "error" and "k.csv" in err and "\x1b" not in err
    assert len(err) < 3000 and all(len(ln) <= 300 for ln in err.splitlines())
    index = (out / "index.html").read_text()
    assert "<script>alert" not in index and "&lt;script&gt;alert(1)&lt;/script&gt;" in index


def test_package_folders_never_clash(tmp_path):
    src = tmp_path / "src"
    text = (EXAMPLES / "ejemplo9rt.toml").read_text(encoding="utf-8")
    names = {"a/one.toml": "Cam", "b/two.toml": "cam", "c/three.toml": "index.html", "d/four.toml": "MANIFEST.json",
             "e/five.toml": "Cam_2"}
    for rel, name in names.items():
        (src / rel).parent.mkdir(parents=True, exist_ok=True)
        (src / rel).write_text(text.replace('name = "Ejemplo9RT"', f"name = {json.dumps(name)}"), encoding="utf-8")
    out = tmp_path / "out"
    assert main(["package", str(src), "-o", str(out), "--outputs", "lift_table"]) == 0
    assert (out / "manifest.json").is_file() and (out / "index.html").is_file()
    cams = json.loads((out / "manifest.json").read_text())["cams"]
    folders = {Path(c["source"]).relative_to(src).as_posix(): c["folder"] for c in cams}
    assert folders == {"a/one.toml": "Cam", "b/two.toml": "cam_2", "c/three.toml": "index.html_2",
                       "d/four.toml": "MANIFEST.json_2", "e/five.toml": "Cam_2_2"}
    assert all(c["status"] == "ok" and c["name"] == names[Path(c["source"]).relative_to(src).as_posix()]
               for c in cams)
    for c in cams:  # every cam's files are its own, and hash as recorded
        assert {f["path"].split("/")[0] for f in c["files"]} == {c["folder"]}
        for f in c["files"]:
            assert (out / f["path"]).is_file()
    # a second run is up to date: the same folders
    assert main(["package", str(src), "-o", str(out), "--outputs", "lift_table"]) == 0
    again = json.loads((out / "manifest.json").read_text())["cams"]
    assert [c["folder"] for c in again] == [c["folder"] for c in cams] and not any(c["rebuilt"] for c in again)


def test_package_refuses_outside_knot_files_unless_allowed(tmp_path):
    (tmp_path / "k.csv").write_text(KNOTS, encoding="utf-8")
    src = tmp_path / "src"
    _knot_design(src, "../k.csv")
    out = tmp_path / "out"
    assert main(["package", str(src), "-o", str(out), "--outputs", "lift_table"]) == 2
    (entry,) = json.loads((out / "manifest.json").read_text())["cams"]
    assert "motion_table.file" in entry["error"] and "outside" in entry["error"]
    assert main(["package", str(src), "-o", str(out), "--outputs", "lift_table", "--allow-outside-files"]) in (0, 1)
    (entry,) = json.loads((out / "manifest.json").read_text())["cams"]
    assert entry["status"] != "error" and entry["files"]
    assert np.isfinite(entry["tolerance_mm"])


def test_terminal_output_has_no_control_characters(tmp_path, capsys):
    """A name with terminal escape sequences (set the title, clear the screen) is printed as plain text."""
    name = "\x1b]0;pwned\x07cam\x1b[2J"
    d = tmp_path / "d.toml"
    text = (EXAMPLES / "ejemplo9rt.toml").read_text(encoding="utf-8")
    d.write_text(text.replace('name = "Ejemplo9RT"', f"name = {json.dumps(name)}"), encoding="utf-8")
    assert main(["check", str(d)]) == 0
    assert main(["motion", str(d)]) == 0
    assert main(["export", str(d), "--dxf", "-o", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert plain(name) in out and "\x1b" not in out and "\x07" not in out
