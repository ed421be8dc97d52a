"""Design files of pure-rolling bevel pairs with a preset TE (``[design] kind =
"preset_te_bevel"``), validation, and the flank grids the ``gearjax surface`` command
exports ([Preset-TE-bevel]).

Schema (file units: mm, degrees, arc-seconds; every geometry key is required except
``[flanks] spiral_R0_mm``)::

    [design]  kind = "preset_te_bevel", name, description (optional strings)
    [pair]    teeth_pinion (int 3..200), teeth_gear (int 3..400, >= teeth_pinion),
              shaft_angle_deg (30..150), outer_transverse_module_mm (0.1..100),
              face_width_mm (> 0, <= 0.5 outer cone distance),
              spiral_angle_deg (5..60), normal_pressure_angle_deg (5..35)
    [flanks]  profile_radius_pinion_mm, profile_radius_gear_mm (0.5..5000),
              addendum_mm, dedendum_mm (0.05..3 module, the working flank heights above
              and below the pitch cone), spiral_R0_mm (optional, > 0; default
              sqrt(A_i A_o) cos delta1, which puts t_m = 0)
    [preset]  te_arcsec (0..600: pinion rotation at the toe and heel ends of the
              contact curve, the seed's 36; 0 = the unmodified pure-rolling pair)

Units inside: mm, rad.
"""

from __future__ import annotations

import copy
import functools
from dataclasses import dataclass, field

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.errors import check_int
from gearjax.gears.preset_bevel.geometry import (PresetBevelDesign, cone_distances, curve_data,
                                                 curve_parameter, flank_phase, gear_curve,
                                                 gear_flank_point, pinion_flank_point,
                                                 pitch_angles, validate_fields)
from gearjax.io import (DesignFileMixin, FlankGrid, check_integer, check_keys, check_number,  # noqa: F401
                        register_design_kind, require_key)
from gearjax.newton import newton_solve
from gearjax.tca.result import register_family

__all__ = ["KIND", "PresetBevelFile", "read_preset_bevel", "validate_fields", "FlankGrid",
           "flank_grid", "SCHEMA"]

KIND = "preset_te_bevel"

#: table -> {key: (unit, lo, hi)} (documentation and validation)
SCHEMA = {
    "pair": {"teeth_pinion": ("", 3, 200), "teeth_gear": ("", 3, 400),
             "shaft_angle_deg": ("deg", 30.0, 150.0),
             "outer_transverse_module_mm": ("mm", 0.1, 100.0),
             "face_width_mm": ("mm", 0.0, None), "spiral_angle_deg": ("deg", 5.0, 60.0),
             "normal_pressure_angle_deg": ("deg", 5.0, 35.0)},
    "flanks": {"profile_radius_pinion_mm": ("mm", 0.5, 5000.0),
               "profile_radius_gear_mm": ("mm", 0.5, 5000.0),
               "addendum_mm": ("mm", None, None), "dedendum_mm": ("mm", None, None),
               "spiral_R0_mm": ("mm", 0.0, None)},
    "preset": {"te_arcsec": ("arcsec", 0.0, 600.0)},
}
_OPTIONAL = {("flanks", "spiral_R0_mm")}


def _grid_point(fn, data, outward_sign, delta, L, H, t0):
    """Solve ``|S(u, t)| = L``, ``h(S) = H`` for (u, t) (mm)."""
    def F(x, th):
        q = fn(th[0], x)
        r = jnp.linalg.norm(q[:2])
        return jnp.stack([jnp.linalg.norm(q) - th[1], r * jnp.cos(th[2]) - q[2] * jnp.sin(th[2])
                          - th[3]])
    sol = newton_solve(F, jnp.stack([0.0, t0]), (data, L, delta, H), tol=1e-10, max_steps=40)
    q = fn(data, sol.x)
    J = jax.jacfwd(lambda x: fn(data, x))(sol.x)
    n = jnp.cross(J[:, 0], J[:, 1])
    n = n / jnp.linalg.norm(n)
    return q, n, sol.x, sol.residual, sol.converged


def flank_grid(des: PresetBevelDesign, member: str, flank: str, n_u: int, n_v: int) -> FlankGrid:
    """Flank grid of ``member`` ("pinion"/"gear"), ``flank`` ("concave"/"convex"): n_u
    cone distances from toe to heel x n_v heights from -dedendum to +addendum (concrete;
    every point a converged solve).  A :class:`gearjax.io.FlankGrid`: ``points``,
    ``normals`` (n_u, n_v, 3; outward normals, mm), ``params`` (n_u, n_v, 3) = (height
    above the pitch cone mm, curve parameter t rad, profile parameter u rad), ``xi``
    (n_u,) face position (L - A_i)/b, ``residual`` (mm) and ``converged`` of the point
    solves."""
    if member not in ("pinion", "gear"):
        raise ValueError(f"member = {member!r} must be 'pinion' or 'gear'")
    if flank not in ("concave", "convex"):
        raise ValueError(f"flank = {flank!r} must be 'concave' or 'convex'")
    n_u, n_v = check_int("n_u", n_u, 2, 2001), check_int("n_v", n_v, 2, 2001)
    ph = flank_phase(des, member, flank)
    d1, d2 = pitch_angles(des)
    if member == "pinion":
        data, fn, delta = curve_data(des, "pinion", flank, ph), pinion_flank_point, d1
    else:
        pin = "concave" if flank == "convex" else "convex"
        data, fn, delta = curve_data(des, "gear", pin, ph, modified=False), gear_flank_point, d2
    Ai, _, Ao = cone_distances(des)
    Ls = jnp.linspace(Ai, Ao, n_u)
    Hs = jnp.linspace(-des.dedendum, des.addendum, n_v)
    LL, HH = jnp.meshgrid(Ls, Hs, indexing="ij")
    T0 = curve_parameter(des, LL)
    q, n, x, res, conv = _grid_jit(fn, data, delta, LL.ravel(), HH.ravel(), T0.ravel())
    # outward normal: the construction normal n (pinion, points to the tip side) or -n2
    # (gear: n2 is the pinion's outward normal, pointing into the gear tooth)
    ref = jax.vmap(lambda t: (gear_curve(data, t)[2] * -1.0 if member == "gear"
                              else _pinion_normal(data, t)))(x[:, 1])
    n = n * jnp.sign(jnp.sum(n * ref, axis=1))[:, None]
    sh = (n_u, n_v)
    params = jnp.stack([HH.ravel(), x[:, 1], x[:, 0]], axis=1)
    return FlankGrid(np.asarray(q).reshape(sh + (3,)), np.asarray(n).reshape(sh + (3,)),
                     np.asarray(params).reshape(sh + (3,)),
                     np.asarray((Ls - Ai) / des.face_width), np.asarray(res).reshape(sh),
                     np.asarray(conv).reshape(sh))


def _pinion_normal(data, t):
    from gearjax.gears.preset_bevel.geometry import curve_frame
    return curve_frame(data, t)[2]


@functools.partial(jax.jit, static_argnames=("fn",))
def _grid_jit(fn, data, delta, L, H, T0):
    return jax.vmap(lambda l, h, t0: _grid_point(fn, data, 1.0, delta, l, h, t0))(L, H, T0)


@dataclass(frozen=True)
class PresetBevelFile(DesignFileMixin):
    """A validated preset-TE bevel design file: ``data`` (file units), ``design`` (the
    :class:`PresetBevelDesign` pytree).  Taken by ``gearjax tca``, ``gearjax efficiency``
    (through ``gearjax.run_tca``) and ``gearjax surface``."""

    data: dict = field(compare=True)
    design: PresetBevelDesign = field(compare=False)

    def defaults_lines(self) -> list:
        """The documented defaults this design relies on (printable lines)."""
        if "spiral_R0_mm" in self.data.get("flanks", {}):
            return []
        return [f"flanks.spiral_R0_mm = {float(self.design.R0):.6g}  # mm, sqrt(A_i A_o) cos "
                "delta1 (t_m = 0)"]

    def surface_grid(self, member: str, flank: str, n_u: int, n_v: int) -> FlankGrid:
        return flank_grid(self.design, member, flank, n_u, n_v)

    def teeth(self, member: str) -> int:
        if member not in ("pinion", "gear"):
            raise ValueError(f"member = {member!r} must be 'pinion' or 'gear'")
        return self.design.z1 if member == "pinion" else self.design.z2


def read_preset_bevel(data: dict) -> PresetBevelFile:
    """Validate a parsed ``preset_te_bevel`` design file (ValueError naming the table and
    the key) and build the design."""
    check_keys("", data, {"design", "pair", "flanks", "preset"})
    check_keys("design", data["design"], {"kind", "name", "description"})
    vals = {}
    for table, keys in SCHEMA.items():
        d = require_key("", data, table) if table in data else None
        if d is None:
            raise ValueError(f"missing table [{table}]")
        check_keys(table, d, set(keys))
        for k, (unit, lo, hi) in keys.items():
            if (table, k) in _OPTIONAL and k not in d:
                continue
            raw = require_key(table, d, k)
            vals[k] = (check_integer(table, k, raw, 1) if k.startswith("teeth")
                       else check_number(table, k, raw, unit))
    try:
        des = validate_fields(dict(
            z1=vals["teeth_pinion"], z2=vals["teeth_gear"], beta_deg=vals["spiral_angle_deg"],
            alpha_n_deg=vals["normal_pressure_angle_deg"], shaft_angle_deg=vals["shaft_angle_deg"],
            module_t=vals["outer_transverse_module_mm"], face_width=vals["face_width_mm"],
            rho1=vals["profile_radius_pinion_mm"], rho2=vals["profile_radius_gear_mm"],
            addendum=vals["addendum_mm"], dedendum=vals["dedendum_mm"],
            preset_te_arcsec=vals["te_arcsec"], R0=vals.get("spiral_R0_mm")))
    except ValueError as exc:
        raise ValueError(f"{exc} (file keys: [pair], [flanks], [preset]; see "
                         "docs/preset_te_bevel.md)") from None
    return PresetBevelFile(copy.deepcopy(data), des)


register_design_kind(KIND, read_preset_bevel)


def _register():
    from gearjax.gears.preset_bevel.tca import ADAPTER
    register_family(PresetBevelFile, ADAPTER)


_register()
