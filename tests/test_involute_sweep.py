"""Seeded sweep of involute pairs against ISO 21771 closed forms (issue: right on every
valid gear).  The sampler, the closed forms (written from tooth diameters, independent
of the library's roll-distance code) and the per-pair checks are those of
``experiments/involute_sweep.py`` (its docstring lists them); the experiment runs 320
pairs, this test a seeded subset of conjugate pairs on both sides.  All pairs share one
compiled TCA program (tooth numbers are traced).

Planted bugs each check catches: the radius-only form-circle boundary (the envelope's
second branch taken for flank: spurious tip contacts of 2000+ arcsec on small shifted
pinions -- the defect this sweep was written for; it fails the TE, flag and path
checks), a contact ratio measured along the solved helical curve instead of the
transverse section (eps_alpha off by ~1 %), a wrong sign of the rack's base-circle
coordinate (paths cut short near the start of active profile), a default grid too short
for high contact ratios (contact ratio not found), a refusal missing or misplaced at a
tooth-form limit (classification and the bisected limits below).
"""

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

import gearjax as gj

_spec = importlib.util.spec_from_file_location(
    "involute_sweep", Path(__file__).parents[1] / "experiments" / "involute_sweep.py")
sweep = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(sweep)

# the two pairs of the defect report, two more small shifted pinions and a pinion with
# negative shifts whose path starts near its base circle
DEFECT_PAIRS = [
    dict(z1=18, z2=30, m=3.0, alpha=20.0, helix=0.0, x1=0.3, x2=0.1, b=20.0, crown=0.0),
    dict(z1=16, z2=24, m=4.5, alpha=20.0, helix=0.0, x1=0.1, x2=0.0, b=40.0, crown=0.0),
    dict(z1=14, z2=35, m=2.0, alpha=20.0, helix=0.0, x1=0.4, x2=0.2, b=16.0, crown=0.0),
    dict(z1=12, z2=29, m=5.0, alpha=25.0, helix=10.0, x1=0.5, x2=-0.1, b=50.0, crown=0.0),
    # negative shifts, start of active profile 2.3 mm of roll from the base circle: the
    # branch test's base-circle coordinate taken from the shifted datum line cut this
    # path short at the start (found by the 40-pair run, seed 1)
    dict(z1=25, z2=67, m=6.0, alpha=18.732686357694856, helix=5.36166788988659,
         x1=-0.2337805667829307, x2=-0.12783598720467093, b=60.0, crown=0.0),
]


@pytest.mark.parametrize("d", DEFECT_PAIRS, ids=lambda d: f"{d['z1']}x{d['z2']}")
def test_small_shifted_pinions_are_conjugate(d):
    """TE p-t-p 2447.6 and 2840.4 arcsec with a 'tip contact' warning before the fix."""
    row = sweep.check_pair(d)
    assert row["status"] == "accepted" and row["expected"] == "valid"
    assert row["fails"] == [], row["fails"]
    for side in ("drive", "coast"):
        assert row[side]["ptp_arcsec"] < 0.01
        assert not row[side]["flags"]["tip_contact"]


def _sample(n, seed):
    rng = np.random.default_rng(seed)
    return [sweep.sample(rng, crowned_share=0.0) for _ in range(n)]


def test_seeded_sweep_of_the_design_space():
    """32 random pairs (spur and helical, alpha_n 14.5-25 deg, z1 from the undercut limit
    to 80, ratio 1-7, shifts -0.6..1.2): refused exactly where the closed forms say
    invalid; every accepted pair conjugate with the ISO 21771 contact ratios, its path
    on the line of action from the start of active profile to the tip, no flag."""
    rows = [sweep.check_pair(d) for d in _sample(32, 7)]
    # known limitation (open, docs/tca.md): a helical pair in line contact is solved
    # along one curve of its contact lines; where that curve's on-flank interval is
    # shorter than a pitch (eps_alpha near 1, large helix angle) the envelope hands
    # over across a gap and the edge_contact flag is raised although other face-width
    # sections are in contact.  Only that flag, on helical pairs, is tolerated.
    known = "flags: edge_contact"
    fails = [(r["design"], r["fails"]) for r in rows if r["fails"]
             and not (r["design"]["helix"] > 0
                      and all(f.split(": ", 1)[1] == known for f in r["fails"]))]
    assert not fails, fails
    assert sum(1 for r in rows if r["fails"]) <= 2
    accepted = [r for r in rows if r["status"] == "accepted"]
    assert len(accepted) >= 15                       # the sweep is not all refusals
    assert any(r["design"]["helix"] > 0 for r in accepted)
    assert any(r["design"]["helix"] == 0 for r in accepted)


def test_refusal_exactly_at_the_undercut_limit():
    """The pinion shift at which the library starts to accept a 12-tooth pinion equals
    the closed-form undercut limit x_min = 1 - z sin^2(alpha_t)/(2 cos beta) (rack tip
    line through the base-circle tangency point), to the bisection's resolution."""
    for z, alpha, beta in ((12, 20.0, 0.0), (10, 25.0, 20.0)):
        at = math.atan(math.tan(math.radians(alpha)) / math.cos(math.radians(beta)))
        limit = 1.0 - z * math.sin(at) ** 2 / (2 * math.cos(math.radians(beta)))
        lo, hi = limit - 0.2, limit + 0.2
        assert not _accepts(z, 60, alpha, beta, lo, 0.0) and _accepts(z, 60, alpha, beta, hi, 0.0)
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if _accepts(z, 60, alpha, beta, mid, 0.0) else (mid, hi)
        assert abs(hi - limit) < 1e-9, (z, hi, limit)


def _accepts(z1, z2, alpha, beta, x1, x2):
    try:
        gj.involute.InvolutePair.create(z1, z2, 1.0, alpha, beta, x1, x2)
        return True
    except ValueError:
        return False


def test_signed_roll_derivative_is_finite_at_and_inside_the_base_circle():
    """The boundary margins enter the optimisers' penalty (``TCAResult.mask_check``) and
    are differentiated in reverse mode: points at or inside the base circle (off the
    flank, e.g. a path continued past its root) must give finite derivatives (the
    plain ``sqrt(max(R^2 - r_b^2, 0))`` gave NaN there and turned a 20-step Adam run on
    x1 into NaN), and outside the derivative is the closed form ``R/rho dR``."""
    import jax
    import jax.numpy as jnp
    from gearjax.gears.involute.limits import flank_limits, signed_roll
    des = gj.involute.InvoluteTCA.create(gj.involute.InvolutePair.create(25, 41, 2.0, 20.0), 20.0)
    lim, _, _ = flank_limits(des)
    rb = float(lim.rb)

    def total(scale):
        q = jnp.stack([jnp.array([0.0, rb * s, 0.0]) for s in (0.9, 1.0)]) * scale
        return jnp.sum(signed_roll(lim, q, jnp.zeros(2)))

    assert np.isfinite(float(jax.grad(total)(1.0)))
    R = 1.2 * rb
    rho = math.sqrt(R ** 2 - rb ** 2)
    g = jax.grad(lambda r: signed_roll(lim, jnp.stack([0.0, r, 0.0]), 0.0))(R)
    assert float(g) == pytest.approx(R / rho, rel=1e-12)
