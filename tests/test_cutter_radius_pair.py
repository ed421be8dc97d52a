"""Seed 000 on a machine-cut pair (gearjax.studies.cutter_radius_pair, gearjax.gears.hypoid.contact_kinematics):
the seed's cutter cone as a formate gear, the pinion it generates, TCA contact points,
and the kinematics there against the seed's eigenfunction model."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gearjax.gears.hypoid import tca as th
from gearjax.gears.hypoid.contact_kinematics import path_kinematics
from gearjax.studies import cutter_radius as hk
from gearjax.studies.cutter_radius_pair import study_pair, study_uv
from gearjax.tca import ARCSEC


@pytest.fixture(scope="module")
def conj():
    inp = hk.study_blank_input(95.25)
    sp = study_pair(inp, hk.StudySettings.make(95.25), "convex")
    prep = th.prepare(sp.pair)
    out = th.hypoid_tca(prep, line_contact=True, steps_per_pitch=8, half_pitches=1.0, n_pairs=3,
                        strict=False)
    return sp, prep, out


def test_machine_settings_of_the_seed_cone(conj):
    sp, _, _ = conj
    g, p = sp.pair.gear.machine, sp.pair.pinion.machine
    assert not g.generated and p.generated
    # the seed's cutter axis is the pitch-plane normal: untilted formate gear whose
    # machine root angle is the gear pitch angle
    assert float(g.tilt) == pytest.approx(0.0, abs=1e-12)
    assert float(g.machine_root_angle) == pytest.approx(float(sp.setup.blank["delta2"]), abs=1e-12)
    assert float(p.ratio_of_roll) == pytest.approx(39 / 6, rel=1e-15)
    assert abs(float(p.blank_offset)) == pytest.approx(35.0, rel=1e-12)
    assert sp.info["chain_error"] < 1e-10


def test_machine_cut_pair_is_conjugate(conj):
    _, _, out = conj
    ok = np.asarray(out.path.converged)
    on = ok & (np.asarray(out.margin) >= 0.0)
    assert ok.all() and on.sum() >= 9
    assert np.max(np.abs(np.asarray(out.path.te))) / ARCSEC < 1e-6


def test_contact_kinematics_equal_the_seed_model(conj):
    """At the TCA contact points: (i) the seed model evaluated by its own module at the
    mapped flank parameters, (ii) the eigenfunctions in the TCA frame, (iii) the pair
    route (contact-point velocity from the TCA, both flanks' curvatures) agree."""
    sp, prep, out = conj
    k = path_kinematics(prep.pair, out.path, line_contact=True)
    uv = study_uv(sp, out.path.p2_body)
    f = jax.vmap(lambda q: hk._point(sp.setup, q))(jnp.asarray(uv))
    assert np.asarray(f.converged).all()
    for name in ("u1", "u2", "u_e", "u_s", "srr", "r_eff", "phi_I", "phi_II", "k_II"):
        seed = np.asarray(getattr(f, name))
        model = np.asarray(getattr(k.model, name))
        assert np.max(np.abs(model - seed) / np.abs(seed)) < 1e-9, name
    for name in ("u1", "u2", "u_e", "u_s", "srr", "r_eff"):
        pair = np.asarray(getattr(k, name))
        seed = np.asarray(getattr(f, name))
        assert np.max(np.abs(pair - seed) / np.abs(seed)) < 1e-9, name
    # line contact: no relative curvature along the contact line; a rank-1 tensor
    assert np.max(np.abs(np.asarray(k.k_along))) < 1e-9 * np.min(np.abs(np.asarray(k.k_rel)))
    assert np.max(np.abs(np.asarray(k.lam_min))) < 1e-9 * np.min(np.asarray(k.lam_max))
