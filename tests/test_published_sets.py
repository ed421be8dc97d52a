"""Published gear sets packaged as examples (issue: right on every valid gear, item 5).

The index of the published sets, what each source prints and where each figure is
tested: docs/reliability.md, "Published gear sets".  This file holds the checks of the
involute design-file kind and of the two [KHK] calculation examples packaged with it
(``example:khk_spur_12x24``, ``example:khk_helical_12x60``); their printed operating
pressure angles, centre distances and diameters are compared digit by digit in
tests/test_involute.py (``test_profile_shifted_pairs_match_published_examples``, which
loads these example files).  Here: the packaged pairs through the whole TCA against the
ISO 21771 closed forms of experiments/involute_sweep.py (written from diameters,
independent of the library's roll-distance code), the command on the example file, and
the file's validation.

Planted bugs these catch: a design-file key read into the wrong field (x1/x2 swapped,
helix in radians: the published centre distance and the closed forms differ), the file
adapter running a different design than the file's pytree (file vs pytree results not
identical), a default grid not applied to involute design files (contact ratio not
found on the 12/24 pair, eps_alpha 1.35 needs the auto grid), a refusal that loses the
table name.
"""

import importlib.util
import json
import math
from pathlib import Path

import numpy as np
import pytest

import gearjax as gj
from gearjax.cli import main

_spec = importlib.util.spec_from_file_location(
    "involute_sweep", Path(__file__).parents[1] / "experiments" / "involute_sweep.py")
sweep = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(sweep)

KHK = ("khk_spur_12x24", "khk_helical_12x60")


def _params(name):
    """The sweep's design dict from the packaged file's [pair] table (file units)."""
    pr = gj.load_design(f"example:{name}").data["pair"]
    return dict(z1=pr["z1"], z2=pr["z2"], m=pr["normal_module_mm"],
                alpha=pr["normal_pressure_angle_deg"], helix=pr.get("helix_angle_deg", 0.0),
                x1=pr.get("profile_shift1", 0.0), x2=pr.get("profile_shift2", 0.0),
                b=pr["face_width_mm"], crown=0.0)


@pytest.mark.parametrize("name", KHK)
def test_khk_examples_are_conjugate_with_the_iso21771_contact_ratios(name):
    """Both sides: TE p-t-p < 0.01 arcsec, eps_alpha (and eps_beta) = ISO 21771 within
    1e-3, the path on the line of action from the start of active profile to the tip,
    no quality flag (measured: 12/24 eps_alpha 1.347796, 12/60 eps_alpha 1.294672,
    eps_beta 0.795775; TE ~1e-10 arcsec)."""
    d = _params(name)
    row = sweep.check_pair(d)
    assert row["expected"] == "valid" and row["status"] == "accepted"
    assert row["fails"] == [], row["fails"]
    ref = sweep.iso21771(d["z1"], d["z2"], d["m"], d["alpha"], d["helix"], d["x1"], d["x2"],
                         d["b"])
    for side in ("drive", "coast"):
        assert row[side]["eps_alpha"] == pytest.approx(ref["eps_alpha"], rel=1e-6)
    # the published centre distances (a = 56.4999 mm and 125.000 mm) from the closed form
    # of the file's inputs, to the printed digits
    a_pub = {"khk_spur_12x24": (56.4999, 5e-5), "khk_helical_12x60": (125.000, 5e-4)}[name]
    assert abs(ref["aw"] - a_pub[0]) <= a_pub[1]


def test_design_file_and_its_pytree_give_identical_tca():
    f = gj.load_design("example:khk_helical_12x60")
    assert isinstance(f, gj.involute.InvoluteFile) and isinstance(f.design, gj.involute.InvoluteTCA)
    r_file, r_tree = gj.run_tca(f, side="coast"), gj.run_tca(f.design, side="coast")
    for a, b in ((r_file.path.te, r_tree.path.te), (r_file.path.point, r_tree.path.point)):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))
    assert float(r_file.contact_ratio) == float(r_tree.contact_ratio)
    # the loaded chain gets the pytree back from the adapter's mesh set-up and runs it
    # through the same adapter (the file adapter takes a pytree as is)
    # (the spur example: the loaded contact of a helical pair in line contact is refused)
    spur = gj.load_design("example:khk_spur_12x24")
    ad = gj.tca.family_of(spur)
    _, _, run_des = ad.mesh(spur, side="coast")
    assert run_des is spur.design
    np.testing.assert_array_equal(np.asarray(ad.run(run_des, side="coast").path.te),
                                  np.asarray(gj.run_tca(spur, side="coast").path.te))
    fn = gj.tca_function(f, side="coast")
    assert fn.pair is f.design
    np.testing.assert_array_equal(np.asarray(fn(f.design).path.te), np.asarray(r_tree.path.te))


def test_tca_command_on_the_packaged_involute_example(capsys):
    """The command takes the involute design file like the inline form: the family's
    default grid (pitches reported), the same result as the inline DESIGN."""
    assert main(["tca", "example:khk_spur_12x24", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert main(["tca", "involute:z1=12,z2=24,m=3,alpha=20,b=20,x1=0.6,x2=0.36", "--json"]) == 0
    inline = json.loads(capsys.readouterr().out)
    assert data["input"]["pitches"] == inline["input"]["pitches"]
    assert data["contact_ratio"] == inline["contact_ratio"]
    assert data["te_arcsec"] == inline["te_arcsec"]
    ref = sweep.iso21771(12, 24, 3.0, 20.0, 0.0, 0.6, 0.36, 20.0)
    assert data["contact_ratio"] == pytest.approx(ref["eps_alpha"], rel=1e-6)
    assert all(data["quality"][k] is False for k in ("edge_contact", "tip_contact",
                                                     "low_contact_ratio"))


@pytest.mark.parametrize("edit,match", [
    (lambda d: d["pair"].pop("normal_module_mm"), r"\[pair\].*normal_module_mm"),
    (lambda d: d["pair"].update(z1=12.0), r"\[pair\] z1 = 12.0 must be an integer"),
    (lambda d: d["pair"].update(helix_angle_deg=75.0), r"\[pair\] helix.*75"),
    (lambda d: d["pair"].update(profile_shift1=1.5), r"\[pair\].*pointed"),
    (lambda d: d["pair"].update(face_width_mm=0.0), r"face_width"),
    (lambda d: d.update(modification={"lead_crown": 0.001}), r"modification\.lead_crown"),
    (lambda d: d["pair"].update(colour="red"), r"pair\.colour"),
])
def test_involute_design_file_refusals(edit, match):
    data = gj.load_design("example:khk_spur_12x24").to_dict()
    edit(data)
    with pytest.raises(ValueError, match=match):
        gj.design_from_dict(data)


def test_involute_design_file_defaults_are_listed():
    lines = gj.load_design("example:khk_spur_12x24").defaults_lines()
    assert "pair.helix_angle_deg = 0" in lines
    assert not any(k.startswith("pair.profile_shift") for k in lines)
    assert math.isclose(float(gj.load_design("example:khk_spur_12x24").design.face_width), 20.0)


def test_involute_design_file_material_sets_e_prime():
    """An involute file's optional [material] is the design's material (E' and the tooth
    compliance, gearjax.loading.materials); without it the documented steel default applies."""
    from gearjax.loading.materials import SOURCE_DEFAULT, SOURCE_DESIGN
    f = gj.load_design("example:khk_spur_12x24")
    assert f.material() is None and gj.pair_material(f).source == SOURCE_DEFAULT
    data = f.to_dict()
    data["material"] = {"youngs_modulus_GPa": 110.0, "poisson": 0.34}
    m = gj.pair_material(gj.design_from_dict(data))
    assert m.source == SOURCE_DESIGN and m.youngs_modulus_MPa == 110000.0
    assert m.e_prime_MPa == pytest.approx(110000.0 / (1 - 0.34 ** 2), rel=1e-14)
    data["material"] = {"youngs_modulus_GPa": 1.1e5, "poisson": 0.34}      # typed in MPa
    with pytest.raises(ValueError, match=r"\[material\] youngs_modulus_GPa"):
        gj.design_from_dict(data)
