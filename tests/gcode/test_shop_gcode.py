"""G-code a shop can run as it comes (issue 13): cutting data from the tool-and-material table, a breakthrough
allowance, entry outside the stock, the stock in the header, and the bore milled by helical interpolation.

Every program is read back by camfab's parser (and the entry by shapely); the expected cutting data are
computed here from the table file itself with the handbook formulas n = 1000 vc / (pi D), f = fz z n."""
from __future__ import annotations

import math
import re
import shutil
import subprocess
import tomllib
from importlib import resources

import numpy as np
import pytest
import shapely

from camfab import pipeline
from camfab.cli import main
from camfab.gcode import dumps, parse
from camfab.gcode.cam import cam_program, verify_cam_program
from camfab.gcode.cutting import cutting_data
from camfab.gcode.toolpath import ENTRY_CLEARANCE_MM
from tests.conftest import EXAMPLES

TOL = 0.01
TABLE = tomllib.loads(resources.files("camfab.gcode").joinpath("cutting_data.toml").read_text(encoding="utf-8"))


def expected(material: str, D: float, tool: str = "carbide") -> tuple[float, float]:
    """(rpm, feed) of the table's row by the handbook formulas, computed here independently."""
    row = TABLE["materials"][material]
    band = next(i for i, edge in enumerate(TABLE["diameter_bands_mm"]) if edge >= D)
    n = round(1000 * row[tool]["vc"] / (math.pi * D))
    return n, row[tool]["fz"][band] * row["flutes"] * n


def design(tmp_path, manufacturing: str = "", machining: str = "", name: str = "d.toml"):
    """Ejemplo9RT (bore 12 mm, plate 10 mm, tool 6 mm) with lines added to [manufacturing] and a [machining]."""
    text = (EXAMPLES / "ejemplo9rt.toml").read_text()
    text = text.replace("[manufacturing]\n", f"[manufacturing]\n{manufacturing}\n")
    if machining:
        text += f"\n[machining]\n{machining}\n"
    p = tmp_path / name
    p.write_text(text)
    return p


def program(path, *flags):
    """``camfab gcode`` of the design at a 0.01 mm tolerance: the text."""
    out = path.with_suffix(".nc")
    assert main(["gcode", str(path), "--tol", str(TOL), "-o", str(out), *flags]) == 0
    return out.read_text()


def spindle_and_feeds(text: str) -> tuple[float, set[float]]:
    bp = parse(text)
    cut = [m for m in bp.moves if m.is_cutting]
    return cut[0].spindle_rpm, {m.feed for m in cut}


@pytest.mark.parametrize("material,D", [("C45", 6.0), ("C45", 16.0), ("AlMgSi1", 6.0), ("100Cr6", 10.0),
                                        ("POM", 3.0), ("GG25", 20.0)])
def test_cutting_data_follow_the_table(material, D):
    n, f = expected(material, D)
    cd = cutting_data(tool_diameter_mm=D, material=f"{material}, as delivered", max_spindle_rpm=1e5)
    assert cd.spindle_rpm == n and cd.feed_mm_min == pytest.approx(f, rel=1e-12)
    assert cd.plunge_feed_mm_min == pytest.approx(TABLE["plunge_fraction"] * f, rel=1e-12)
    hss = cutting_data(tool_diameter_mm=D, material=material, tool_material="hss", max_spindle_rpm=1e5)
    assert hss.spindle_rpm == expected(material, D, "hss")[0] < n  # HSS cuts slower than carbide


def test_programs_differ_by_tool_and_material_as_the_table_says(tmp_path):
    """Two materials x two tools: the S and F words read back are the table's numbers, four different feeds."""
    seen = {}
    for material, D in [("42CrMo4", 8.0), ("42CrMo4", 10.0), ("bronze", 8.0), ("bronze", 10.0)]:
        text = program(design(tmp_path, f'material = "{material}"', name=f"{material}{D:g}.toml"),
                       "--tool-diameter", str(D))
        n, f = expected(material, D)
        rpm, feeds = spindle_and_feeds(text)
        assert rpm == n
        assert feeds == {round(f, 1), round(TABLE["plunge_fraction"] * f, 1)}
        assert f"(cutting data: camfab table, {material})" in text
        seen[material, D] = round(f, 1)
    assert len(set(seen.values())) == 4


def test_the_design_and_the_command_line_override_the_table(tmp_path):
    p = design(tmp_path, 'material = "C45"', "spindle_rpm = 4321.0\ntool_flutes = 2")
    n_table, _ = expected("C45", 6.0)
    rpm, feeds = spindle_and_feeds(program(p))
    fz = TABLE["materials"]["C45"]["carbide"]["fz"][1]
    assert rpm == 4321 != n_table and round(fz * 2 * 4321, 1) in feeds  # the feed follows the given speed
    rpm, feeds = spindle_and_feeds(program(p, "--rpm", "5000", "--feed", "555", "--plunge-feed", "111"))
    assert rpm == 5000 and feeds == {555.0, 111.0}


def test_a_spindle_above_the_machine_maximum_is_limited_and_said(tmp_path):
    p = design(tmp_path, 'material = "AlMgSi1 T6"', "max_spindle_rpm = 12000.0")
    n_table, _ = expected("AlMgSi1", 6.0)
    assert n_table > 12000
    text = program(p)
    rpm, feeds = spindle_and_feeds(text)
    fz = TABLE["materials"]["AlMgSi1"]["carbide"]["fz"][1]
    assert rpm == 12000 and round(fz * 2 * 12000, 1) in feeds  # the same chip load at the highest speed
    assert f"(spindle LIMITED: table {n_table} rpm over machine max 12000)" in text
    assert "(spindle source: 12000 rpm, feed at the same fz, vc 226 m/min)" in text


def test_final_depth_includes_the_breakthrough_and_the_stock_is_stated(tmp_path):
    for brk, text in ((0.5, program(design(tmp_path, name="a.toml"))),
                      (0.0, program(design(tmp_path, machining="breakthrough_mm = 0.0", name="b.toml")))):
        z = [m.end[2] for m in parse(text).moves if m.is_cutting]
        assert min(z) == pytest.approx(-(10.0 + brk), abs=1e-9)
        assert f"(depth: plate 10 + breakthrough {brk:g} = {10 + brk:g} mm)" in text
        assert "(stock: round blank D94 x 10 mm on the axis X0 Y0)" in text  # 2 x (45 + 2)
        assert "(material source: not given in the design, C45 assumed)" in text


@pytest.mark.parametrize("post", ["linuxcnc", "grbl"])
def test_no_plunge_into_the_blank(tmp_path, post):
    """Every move that descends below the stock top with no horizontal travel lies outside the blank by the tool
    radius; every descent inside the blank is the bore's helix (XY and Z together)."""
    text = program(design(tmp_path, machining="stock_allowance_mm = 3.0\nmill_bore = true"), "--post", post)
    m = re.search(r"\(stock: round blank D([\d.]+) x", text)
    blank = shapely.Point(0, 0).buffer(float(m.group(1)) / 2, quad_segs=256)
    moves = parse(text).moves
    plunges = [mv for mv in moves if mv.is_cutting and mv.end[2] < -1e-9 and mv.end[2] < mv.start[2] - 1e-9]
    vertical = [mv for mv in plunges if math.hypot(mv.end[0] - mv.start[0], mv.end[1] - mv.start[1]) < 1e-9]
    assert len(vertical) == 4 + 1  # 10.5 mm in 4 levels of one roughing pass, then the finishing pass at full depth
    for mv in vertical:
        assert blank.distance(shapely.Point(mv.end[:2])) >= 3.0 + ENTRY_CLEARANCE_MM - 1e-3
    assert all(mv.label.startswith("BORE HELIX") for mv in plunges if mv not in vertical)
    # every pass feeds in along one line (the roughing levels cut the slot the finishing pass at full depth follows)
    entries = [mv for mv in moves if mv.kind == "line" and (mv.label or "").endswith("LEAD-IN")
               and abs(mv.end[2] - mv.start[2]) < 1e-9]
    assert len(entries) == len(vertical)
    a = np.array(entries[-1].start[:2])
    d = (np.array(entries[-1].end[:2]) - a) / math.dist(entries[-1].end[:2], a)
    off = [abs(d[0] * (p[1] - a[1]) - d[1] * (p[0] - a[0])) for mv in entries for p in (mv.start, mv.end)]
    # each entry runs along its contour's normal at the start; on a near-straight stretch written as chords (arc
    # radius limit) a chord's normal leans by up to half its angle (0.04 mm over the entry here): well inside the
    # slot the roughing entries cut, so the finishing cutter meets less than half its 0.2 mm allowance there
    assert max(off) < 0.1


def test_the_bore_is_milled_by_a_helix_and_a_finishing_circle(tmp_path):
    text = program(design(tmp_path, machining="mill_bore = true\nhelix_pitch_mm = 0.8"))
    moves = parse(text).moves
    R = (12.0 - 6.0) / 2
    helix = [m for m in moves if m.kind == "arc" and m.label.startswith("BORE HELIX")]
    circle = [m for m in moves if m.kind == "arc" and m.label == "BORE FINISH CIRCLE"]
    for m in helix + circle:
        assert m.center[:2] == pytest.approx((0.0, 0.0), abs=1e-9)
        assert m.radius_start == pytest.approx(R, abs=1e-4) and m.radius_end == pytest.approx(R, abs=1e-4)
        assert not m.clockwise  # climb milling inside the bore with M3
    dz = [m.start[2] - m.end[2] for m in helix]
    assert max(dz) <= 0.8 / 2 + 1e-9 and min(dz) > 0  # at most the pitch per turn, always descending
    assert 2 * max(dz) <= 2 * math.pi * R * math.tan(math.radians(3.0)) + 1e-9  # and at most 3 degrees steep
    assert helix[0].start[2] == pytest.approx(0.0) and helix[-1].end[2] == pytest.approx(-10.5)
    assert {m.end[2] for m in circle} == {-10.5} and abs(sum(m.sweep for m in circle)) == pytest.approx(2 * math.pi)


def test_verify_checks_the_bore_against_its_wall(tmp_path):
    cam = pipeline.load("ejemplo9rt")
    job = pipeline.gcode_job(cam.spec, tol=TOL, overrides={"mill_bore": True})
    contact = cam.geometry.profiles[0]
    text = dumps(cam_program(contact, job, tol=TOL).program, "linuxcnc")
    assert verify_cam_program(text, contact, job, tol=TOL).ok
    # the finishing circle 0.05 mm too large: a gouge into the wall and a deviation
    lines = text.splitlines()
    i = lines.index("(BORE FINISH CIRCLE)")
    lines[i + 1] = lines[i + 1].replace("X-3.0000", "X-3.0500").replace("I-3.0000", "I-3.0500")
    lines[i + 2] = lines[i + 2].replace("X3.0000", "X3.0500").replace("I3.0000", "I3.0500")
    lines.insert(i + 1, "G1 X3.0500")
    rep = verify_cam_program("\n".join(lines) + "\n", contact, job, tol=TOL)
    assert {"GOUGE"} <= {str(c) for c in rep.codes()}
    # the helix is a descending move: it must carry the plunge feed, not the cutting feed
    lines = text.splitlines()
    i = next(k for k, t in enumerate(lines) if t.startswith("G3") and " Z" in t)
    lines[i] += f" F{job.feed_mm_min:.1f}"
    lines[i + 1] += f" F{job.plunge_feed_mm_min:.1f}"
    rep = verify_cam_program("\n".join(lines) + "\n", contact, job, tol=TOL)
    assert {str(c) for c in rep.codes()} == {"FEED_OUT_OF_RANGE"} and rep.problems[0].line == i + 1
    # the same program checked as if the job had no bore: the bore moves cut the part
    plain = pipeline.gcode_job(cam.spec, tol=TOL)
    assert "GOUGE" in {str(c) for c in verify_cam_program(text, contact, plain, tol=TOL).codes()}


@pytest.mark.parametrize("manufacturing,machining,flags,field", [
    ('material = "Unobtainium 7"', "", (), "manufacturing.material"),
    ("", "", ("--material", "brass"), "manufacturing.material"),
    ("", "mill_bore = true", ("--tool-diameter", "12"), "machining.mill_bore"),
    ("", "stock_diameter_mm = 80.0", (), "machining.stock_diameter_mm"),
    ("", "breakthrough_mm = -0.5", (), "machining.breakthrough_mm"),
    ("", "tool_material = \"diamond\"", (), "machining.tool_material"),
    ("", "", ("--tool-diameter", "25"), "manufacturing.tool_diameter_mm"),
    ("", "spindle_rpm = 20000.0", (), "machining.spindle_rpm"),
])
def test_bad_inputs_exit_2_naming_the_field(tmp_path, capsys, manufacturing, machining, flags, field):
    p = design(tmp_path, manufacturing, machining)
    out = tmp_path / "x.nc"
    capsys.readouterr()
    assert main(["gcode", str(p), "--tol", str(TOL), "-o", str(out), *flags]) == 2
    err = capsys.readouterr().err
    assert field in err and not out.exists()
    if field == "manufacturing.material":
        assert all(name in err for name in TABLE["materials"])  # the known ones listed


@pytest.mark.skipif(shutil.which("rs274") is None, reason="LinuxCNC's rs274 interpreter is not installed")
def test_linuxcnc_reads_the_helix_and_the_entry(tmp_path):
    """LinuxCNC's own interpreter runs the program with the bore helix (G3 with Z) and the horizontal entries."""
    text = program(design(tmp_path, machining="mill_bore = true"))
    f = tmp_path / "bore.nc"
    f.write_text(text)
    r = subprocess.run(["rs274", "-g", str(f)], capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)
    out = r.stdout + r.stderr
    assert r.returncode == 0 and "error" not in out.lower() and "PROGRAM_END" in out
    helix = re.findall(r"ARC_FEED\(([^)]*)\)", out)
    zs = [float(a.split(",")[5]) for a in helix]
    assert min(zs) == pytest.approx(-10.5, abs=1e-4) and len(set(np.round(zs, 4))) > 10


def test_a_conventional_inch_program_with_its_bore_verifies(tmp_path, capsys):
    """Conventional milling runs the bore clockwise; in inch the depths read back within the rounding."""
    p = design(tmp_path, machining="mill_bore = true\ndirection = \"conventional\"\nunits = \"inch\"")
    text = program(p)
    helix = [m for m in parse(text).moves if m.kind == "arc" and m.label.startswith("BORE")]
    assert helix and all(m.clockwise for m in helix)
    assert min(m.end[2] for m in helix) == pytest.approx(-10.5, abs=2.54e-4)  # 5 decimals of an inch
    capsys.readouterr()
    assert main(["verify", str(p.with_suffix(".nc")), "--design", str(p), "--tol", str(TOL)]) == 0


@pytest.mark.parametrize("machining", ["", "spindle_rpm = 4321.0\nfeed_mm_min = 500.0\nplunge_feed_mm_min = 200.0",
                                       "max_spindle_rpm = 3000.0"])
def test_each_header_key_is_stated_once(tmp_path, machining):
    """The header is one table of `key: value` lines: the summary (spindle, feed, tool, material ...) and the
    notes that say where each number came from use distinct keys, so a reader (or a script) never finds two
    different `spindle:` lines.  Repeated keys are only continuation notes of the same item (stock, bore)."""
    text = program(design(tmp_path, machining=machining))
    head = text.split("(ROUGH", 1)[0]
    keys = [m.group(1) for m in re.finditer(r"^\(([a-zA-Z /]+?):", head, re.M)]
    repeated = {k for k in keys if keys.count(k) > 1} - {"stock", "bore"}
    assert keys and not repeated, repeated
    if "feed_mm_min" in machining:  # all three given: one line says so
        assert "(cutting data: rpm, feed and plunge feed given)" in head
    else:
        assert "(spindle source:" in head and "(feed source:" in head and "(plunge source:" in head
