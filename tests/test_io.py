"""Design files and exports (gearjax.io): round trip, validation, atomic writes, STL."""

import math
import os
from collections import Counter

import numpy as np
import pytest

from gearjax import io
from gearjax.gears.hypoid.flank import flank_surface
from gearjax.io import dumps_toml, write_csv, write_stl_flank, write_stl_tooth, write_xyz
from gearjax.gears.hypoid.design_file import design_from_dict, load_design, save_design


@pytest.fixture(scope="module")
def design():
    return load_design("example:hft_8x43")


@pytest.fixture(scope="module")
def gear_grids(design):
    return {f: flank_surface(design.flank("gear", f), 4, 3) for f in ("convex", "concave")}


def test_examples_listed_and_valid():
    names = io.list_examples()
    assert "hft_8x43" in names
    for n in names:
        assert io.load_design(f"example:{n}").name == n     # any family, by [design] kind


def test_round_trip_lossless(tmp_path, design):
    p = save_design(design, tmp_path / "d.toml")
    back = load_design(p)
    assert back == design and back.to_dict() == design.to_dict()
    # and again: the writer is stable
    assert dumps_toml(back.data) == p.read_text()


@pytest.mark.parametrize("name", [n for n in io.list_examples() if io.read_toml(
    f"example:{n}")["design"]["kind"] in ("hypoid", "spiral_bevel")])
def test_round_trip_every_example(tmp_path, name):
    """Every packaged design survives save -> load unchanged (dials, inline tables,
    optional keys), and the flank settings rebuilt from the copy are identical."""
    d = load_design(f"example:{name}")
    back = load_design(save_design(d, tmp_path / f"{name}.toml"))
    assert back == d
    for m, f in d.flanks():
        a, b = d.machine(m, f), back.machine(m, f)
        for k in ("radial_distance", "cradle_angle", "tilt", "swivel", "center_to_back"):
            assert float(getattr(a, k)) == float(getattr(b, k))


def test_toml_writer_values(tmp_path):
    import tomllib
    data = {"a": {"x": 1, "y": 0.1, "z": -3.25e-07, "s": 'q"uo\\te', "b": True,
                  "l": [1.0, 2.5], "big": 1e300},
            "n": {"m": {"k": "v"}}}
    assert tomllib.loads(dumps_toml(data)) == data


def _edited(design, path, value):
    d = design.to_dict()
    node = d
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value
    return d


@pytest.mark.parametrize("path,value,msg", [
    (("pinion", "convex", "cutter", "point_radius"), -117.0, "point_radius"),
    (("gear", "concave", "cutter", "blade_angle"), 50.0, "blade_angle"),
    (("gear", "concave", "cutter", "blade_angle"), 0.0, "blade_angle"),
    (("blank_summary", "gear", "face_width"), 200.0, "face_width"),
    (("blank_summary", "gear", "teeth"), 5, "ratio"),
    (("pinion", "convex", "machine", "colour"), 1.0, "pinion.convex.machine.colour"),
    (("blank_summary", "pinion", "shoe_size"), 1.0, "blank_summary.pinion.shoe_size"),
    (("extra",), {"a": 1}, "'.extra'"),
    (("pinion", "convex", "machine", "type"), "hobbed", "type"),
    (("pinion", "convex", "machine", "no116", "eccentric"), 0.0, "eccentric"),
    (("blank", "gear_face_width_mm"), -4.0, "gear_face_width"),
    (("blank", "wrong_key"), 1.0, "wrong_key"),
])
def test_invalid_designs_name_the_field(design, path, value, msg):
    with pytest.raises(ValueError, match=msg):
        design_from_dict(_edited(design, path, value))


def test_mean_cone_distance_consistency(design):
    with pytest.raises(ValueError, match="mean_cone_distance"):
        design_from_dict(_edited(design, ("blank_summary", "pinion", "mean_cone_distance"), 120.0))


def test_csv_and_xyz(tmp_path, gear_grids):
    g = gear_grids["convex"]
    lines = write_csv(tmp_path / "f.csv", g).read_text().splitlines()
    assert lines[0].startswith("i,j,xi,s_mm") and len(lines) == 1 + 4 * 3
    row = lines[1 + 3 * 2 + 1].split(",")                      # i = 2, j = 1
    np.testing.assert_allclose([float(v) for v in row[6:9]], np.asarray(g.points[2, 1]), rtol=1e-15)
    xyz = np.loadtxt(write_xyz(tmp_path / "f.xyz", g))
    np.testing.assert_allclose(xyz[:, :3], np.asarray(g.points).reshape(-1, 3), rtol=1e-11)
    np.testing.assert_allclose(xyz[:, 3:], np.asarray(g.normals).reshape(-1, 3), atol=1e-11)


def _read_stl(path):
    tris, cur = [], []
    for ln in path.read_text().splitlines():
        ln = ln.strip()
        if ln.startswith("vertex"):
            cur.append([float(v) for v in ln.split()[1:]])
            if len(cur) == 3:
                tris.append(cur)
                cur = []
    return np.array(tris)


def test_stl_flank(tmp_path, gear_grids):
    g = gear_grids["concave"]
    tri = _read_stl(write_stl_flank(tmp_path / "f.stl", g))
    assert tri.shape == (2 * 3 * 2, 3, 3)
    fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    ctr = tri.mean(1)
    # facets face the same way as the flank normal (out of the material)
    n_near = np.asarray(g.normals).reshape(-1, 3)[
        np.argmin(np.linalg.norm(np.asarray(g.points).reshape(-1, 3)[None] - ctr[:, None], axis=-1), axis=1)]
    assert np.all(np.einsum("ij,ij->i", fn, n_near) > 0)


def test_stl_tooth_is_closed(tmp_path, design, gear_grids):
    p = write_stl_tooth(tmp_path / "t.stl", gear_grids["convex"], gear_grids["concave"],
                        design.member_blank("gear").teeth)
    tri = _read_stl(p)
    key = lambda v: tuple(np.round(v, 6))
    edges = Counter()
    for t in tri:
        for a, b in ((0, 1), (1, 2), (2, 0)):
            edges[frozenset((key(t[a]), key(t[b])))] += 1
    assert set(edges.values()) == {2}                 # watertight: every edge shared twice
    # consistent outward orientation: enclosed volume (divergence theorem) is positive
    vol = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6
    assert vol > 0
    # tooth thickness is a fraction of the circular pitch
    assert vol < 2 * math.pi * 151.26 ** 2 * 41.0 / 43


def test_atomic_write_keeps_old_file_on_failure(tmp_path, monkeypatch, gear_grids):
    p = tmp_path / "keep.csv"
    p.write_text("old content\n")

    def boom(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(io.files.os, "replace", boom)
    with pytest.raises(OSError, match="disk full"):
        write_csv(p, gear_grids["convex"])
    assert p.read_text() == "old content\n"
    assert sorted(os.listdir(tmp_path)) == ["keep.csv"]   # no temp file left behind


@pytest.mark.parametrize("bad", ["converged", "nan_point", "nan_normal"])
def test_every_format_refuses_a_grid_with_a_point_not_converged(tmp_path, design, gear_grids,
                                                                bad):
    """#28 item 4: one point that is not a converged solve (flag False, or a point or a
    normal not finite) refuses the export in every format, and nothing is written
    (an existing file keeps its content)."""
    g = gear_grids["convex"]
    P, N = np.array(g.points), np.array(g.normals)
    conv = np.array(g.converged, bool)
    if bad == "converged":
        conv[1, 2] = False
    elif bad == "nan_point":
        P[1, 2, 0] = np.nan
    else:
        N[1, 2, 2] = np.inf
    broken = g._replace(points=P, normals=N, converged=conv)
    teeth = design.member_blank("gear").teeth
    writers = {"f.csv": lambda p: write_csv(p, broken), "f.xyz": lambda p: write_xyz(p, broken),
               "f.stl": lambda p: write_stl_flank(p, broken),
               "t1.stl": lambda p: write_stl_tooth(p, broken, gear_grids["concave"], teeth),
               "t2.stl": lambda p: write_stl_tooth(p, gear_grids["concave"], broken, teeth),
               "g.xyz": lambda p: io.write_flank(p, broken)}
    for name, write in writers.items():
        p = tmp_path / name
        p.write_text("old\n")
        with pytest.raises(io.UnconvergedExportError,
                           match=r"1 of 12 grid points are not converged solves"):
            write(p)
        assert p.read_text() == "old\n"
    # the intact grid is written (the check refuses only what is wrong)
    assert write_xyz(tmp_path / "ok.xyz", g).exists()


def test_design_file_with_a_byte_order_mark_loads(tmp_path):
    """A design file saved by an editor that writes a UTF-8 byte-order mark reads as the
    same design (the mark is not TOML)."""
    text = io.read_toml("example:spiral_bevel_10x30")
    src = io.example_path("spiral_bevel_10x30").read_text(encoding="utf-8")
    p = tmp_path / "bom.toml"
    p.write_bytes(b"\xef\xbb\xbf" + src.encode("utf-8"))
    assert io.read_toml(str(p)) == text
    assert load_design(str(p)).to_dict() == load_design("example:spiral_bevel_10x30").to_dict()
