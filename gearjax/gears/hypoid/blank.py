"""Blank design of face-milled spiral-bevel and hypoid gear pairs (public interface).

Three routes to the same blank, chosen by ``BlankInput.method``:

``"iso23509-method0"``  spiral bevel (offset 0), ISO 23509:2016 6.2.1 + clause 7;
``"iso23509-method1"``  hypoid, the Gleason method, ISO 23509:2016 6.2.2 + clause 7
                        (face milling: limit curvature radius = cutter radius);
``"tangent-cones"``  hypoid pitch cones by the tangency of two skew cones
                        ([Tangent-cones], :mod:`gearjax.gears.hypoid.pitch_cones`): two-variable
                        Newton in the pitch angles with the ratio and cutter-radius
                        conditions, contact point at mid face ([Tangent-cones] eq. (7)); the
                        remaining dimensions by ISO 23509 clause 7.

:func:`blank_geometry` is the jit/jacfwd-friendly core (no validation in the traced
part); :meth:`BlankInput.from_dict` validates designer input (file units: mm and
degrees); :func:`blank_sensitivity` gives ``jax.jacfwd`` of every output with
respect to offset, ratio, gear pitch diameter, face width, cutter radius and
spiral angle.

Units inside: mm and rad.  Degrees appear only in ``from_dict``/``to_dict``/
``to_table``.  The geometry does not depend on the hand of spiral (mirror image);
``hand`` only selects the sign of the [Tangent-cones] cradle angle.

References (docs/references.md): [ISO23509]; [Tangent-cones]; docs in
``docs/hypoid_blank.md``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field, fields, make_dataclass

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.errors import check_int, check_range, require_converged
from gearjax.gears.hypoid import iso23509
from gearjax.gears.hypoid import pitch_cones
__all__ = ["METHODS", "METHOD_ALIASES", "FILE_DEFAULTS", "BlankInput", "BlankData", "OUTPUTS", "blank_geometry",
           "blank_sensitivity", "SENSITIVITY_INPUTS"]

METHODS = ("iso23509-method0", "iso23509-method1", "tangent-cones")
#: former names of the methods, still accepted in design files and constructors
METHOD_ALIASES = {"seed003-tangency": "tangent-cones"}
_HANDS = ("left", "right")
_MEMBERS = ("pinion", "gear")

_DEG = math.pi / 180.0


def _deg_exact(rad: float) -> float:
    """Degrees ``d`` of ``rad`` chosen so that ``math.radians(d) == rad`` when possible
    (round trip of ``to_dict``/``from_dict`` without a last-bit drift)."""
    d = math.degrees(rad)
    if math.radians(d) == rad:
        return d
    lo = hi = d
    for _ in range(8):
        lo, hi = math.nextafter(lo, -math.inf), math.nextafter(hi, math.inf)
        for c in (lo, hi):
            if math.radians(c) == rad:
                return c
    return d


# (file key, attribute, kind) ; kind: "deg" angle, "mm" length, "-" number, "str", "int"
_KEYS = [
    ("method", "method", "str"),
    ("z1", "z1", "int"),
    ("z2", "z2", "int"),
    ("hand", "hand", "str"),
    ("spiral_member", "spiral_member", "str"),
    ("taper", "taper", "str"),
    ("shaft_angle_deg", "shaft_angle", "deg"),
    ("offset_mm", "offset", "mm"),
    ("gear_outer_pitch_diameter_mm", "gear_outer_pitch_diameter", "mm"),
    ("gear_face_width_mm", "gear_face_width", "mm"),
    ("spiral_angle_deg", "spiral_angle", "deg"),
    ("cutter_radius_mm", "cutter_radius", "mm"),
    ("pressure_angle_drive_deg", "pressure_angle_drive", "deg"),
    ("pressure_angle_coast_deg", "pressure_angle_coast", "deg"),
    ("limit_pressure_angle_factor", "limit_pressure_angle_factor", "-"),
    ("addendum_factor", "addendum_factor", "-"),
    ("dedendum_factor", "dedendum_factor", "-"),
    ("profile_shift", "profile_shift", "-"),
    ("wheel_addendum_angle_deg", "wheel_addendum_angle", "deg"),
    ("wheel_dedendum_angle_deg", "wheel_dedendum_angle", "deg"),
]
_REQUIRED = ("z1", "z2", "gear_outer_pitch_diameter_mm", "gear_face_width_mm",
             "spiral_angle_deg", "cutter_radius_mm")


@dataclass(frozen=True)
class BlankInput:
    """Designer's input for a face-milled bevel/hypoid blank (mm, rad).

    Static (meta) fields: ``z1, z2`` tooth numbers (pinion, gear; integers with
    1 <= z1 <= 400 and z1 <= z2 <= 2000 -- one-tooth pinions exist in high-ratio
    hypoids, so no larger minimum is imposed); ``method`` one of
    :data:`METHODS`; ``hand`` of spiral of the pinion ("left"/"right");
    ``spiral_member`` whose mean spiral angle ``spiral_angle`` is ("pinion" --
    the ISO Method 1 input -- or "gear"; Method 0 has equal angles); ``taper`` the
    depthwise taper of ISO 23509 annex C.5 ("standard", "uniform",
    "constant-slot", "modified-slot", "manual").

    Sane bounds besides the ranges of :meth:`validate`: gear outer pitch diameter
    and cutter radius at most 1e4 mm (10 m).

    Continuous (data) fields, differentiable: ``shaft_angle`` Sigma (rad, default
    pi/2); ``offset`` hypoid offset E (mm, >= 0, default 0); ``gear_outer_pitch_
    diameter`` d_e2 (mm, the **outer** pitch diameter of the gear); ``gear_face_
    width`` b2 (mm); ``spiral_angle`` mean spiral angle (rad) of ``spiral_member``;
    ``cutter_radius`` r_c0 (mm, mean cutter radius of the face mill);
    ``pressure_angle_drive/coast`` nominal design pressure angles alpha_dD,
    alpha_dC (rad, default 20 deg); ``limit_pressure_angle_factor`` f_alim
    (ISO 23509 (118)-(119), default 1: generated angles balanced about the limit
    pressure angle); ``addendum_factor`` k_hap (default 1.0), ``dedendum_factor``
    k_hfp (default 1.25), ``profile_shift`` x_hm1 (default 0) -- ISO 23509 data
    type I; ``wheel_addendum_angle``, ``wheel_dedendum_angle`` theta_a2, theta_f2
    (rad, used only with ``taper="manual"``).
    """

    z1: int
    z2: int
    gear_outer_pitch_diameter: float
    gear_face_width: float
    spiral_angle: float
    cutter_radius: float
    method: str = "iso23509-method1"
    hand: str = "left"
    spiral_member: str = "pinion"
    taper: str = "standard"
    shaft_angle: float = math.pi / 2
    offset: float = 0.0
    pressure_angle_drive: float = 20.0 * _DEG
    pressure_angle_coast: float = 20.0 * _DEG
    limit_pressure_angle_factor: float = 1.0
    addendum_factor: float = 1.0
    dedendum_factor: float = 1.25
    profile_shift: float = 0.0
    wheel_addendum_angle: float = 0.0
    wheel_dedendum_angle: float = 0.0

    @classmethod
    def from_dict(cls, d: dict) -> "BlankInput":
        """Build from a TOML ``[blank]`` table in file units (mm, degrees), validated.

        Keys (defaults in brackets): ``method`` ["iso23509-method1"], ``z1``, ``z2``,
        ``hand`` ["left"], ``spiral_member`` ["pinion"], ``taper`` ["standard"],
        ``shaft_angle_deg`` [90], ``offset_mm`` [0], ``gear_outer_pitch_diameter_mm``,
        ``gear_face_width_mm``, ``spiral_angle_deg``, ``cutter_radius_mm``,
        ``pressure_angle_drive_deg`` [20], ``pressure_angle_coast_deg`` [20],
        ``limit_pressure_angle_factor`` [1], ``addendum_factor`` [1.0],
        ``dedendum_factor`` [1.25], ``profile_shift`` [0], ``wheel_addendum_angle_deg``
        [0], ``wheel_dedendum_angle_deg`` [0] (:data:`FILE_DEFAULTS`).  Raises
        ``ValueError`` with one line naming the field, its value and the allowed
        range; a string, boolean or array where a number is expected, a float
        tooth number, NaN and inf are refused.
        """
        if not isinstance(d, dict):
            raise ValueError(f"[blank] must be a table, got {type(d).__name__}")
        known = {k for k, _, _ in _KEYS}
        for k in d:
            if k not in known:
                raise ValueError(f"unknown key {k!r} in [blank]; allowed keys: "
                                 + ", ".join(sorted(known)))
        for k in _REQUIRED:
            if k not in d:
                raise ValueError(f"[blank] is missing the required key {k!r}")
        kw = {}
        for key, attr, kind in _KEYS:
            if key not in d:
                continue
            v = d[key]
            if kind == "str":
                if not isinstance(v, str):
                    raise ValueError(f"{key} = {v!r} must be a string, got {type(v).__name__}")
                kw[attr] = v
            elif kind == "int":
                if not isinstance(v, (int, np.integer)) or isinstance(v, (bool, np.bool_)):
                    raise ValueError(f"{key} = {v!r} must be an integer, got {type(v).__name__}")
                kw[attr] = check_int(key, v, 1)
            else:
                if (not isinstance(v, (int, float, np.integer, np.floating))
                        or isinstance(v, (bool, np.bool_))):
                    raise ValueError(f"{key} = {v!r} must be a number"
                                     + (f" ({kind})" if kind in ("mm", "deg") else "")
                                     + f", got {type(v).__name__}")
                x = check_range(key, v)
                kw[attr] = math.radians(x) if kind == "deg" else x
        inp = cls(**kw)
        inp.validate()
        return inp

    def to_dict(self) -> dict:
        """File-unit dict (mm, degrees) with every key; ``from_dict(to_dict(x)) == x``."""
        out = {}
        for key, attr, kind in _KEYS:
            v = getattr(self, attr)
            if kind in ("str", "int"):
                out[key] = v
            elif kind == "deg":
                out[key] = _deg_exact(float(v))
            else:
                out[key] = float(v)
        return out

    def __post_init__(self):
        if isinstance(self.method, str) and self.method in METHOD_ALIASES:
            object.__setattr__(self, "method", METHOD_ALIASES[self.method])

    def validate(self) -> "BlankInput":
        """Check concrete values; raise ``ValueError`` naming field, value and range."""
        if self.method not in METHODS:
            raise ValueError(f"method = {self.method!r} is not one of {', '.join(METHODS)}")
        if self.hand not in _HANDS:
            raise ValueError(f"hand = {self.hand!r} is not one of left, right")
        if self.spiral_member not in _MEMBERS:
            raise ValueError(f"spiral_member = {self.spiral_member!r} is not one of pinion, gear")
        if self.taper not in iso23509.TAPERS:
            raise ValueError(f"taper = {self.taper!r} is not one of {', '.join(iso23509.TAPERS)}")
        if self.method == "iso23509-method1" and self.spiral_member != "pinion":
            raise ValueError("spiral_member = 'gear' is not available with method "
                             "iso23509-method1 (its input is the pinion spiral angle); "
                             "use 'pinion' or method tangent-cones")
        z1 = check_int("z1", self.z1, 1, 400)
        z2 = check_int("z2", self.z2, 1, 2000)
        check_range("ratio z2/z1", z2 / z1, 1.0, None)
        # 45 deg <= Sigma and gear pitch angle below 90 deg (no crown/internal gear:
        # u sin(Sigma - 90 deg) < 1, ISO 23509 (11) needs it)
        sig_max = min(135.0, 90.0 + math.degrees(math.asin(min(1.0, z1 / z2))) - 1e-9)
        sig = check_range("shaft_angle_deg", math.degrees(self.shaft_angle), 45.0, sig_max,
                          unit="deg")
        de2 = check_range("gear_outer_pitch_diameter_mm", self.gear_outer_pitch_diameter,
                          0.0, 1e4, lo_open=True, unit="mm")
        # outer cone distance of the bevel pitch cone as the face-width bound
        S = math.radians(sig)
        d2 = S - math.atan2(math.sin(S), z2 / z1 + math.cos(S))
        Re2 = de2 / (2.0 * math.sin(d2))
        check_range("gear_face_width_mm", self.gear_face_width, 0.0, Re2, lo_open=True,
                    hi_open=True, unit="mm")
        check_range("cutter_radius_mm", self.cutter_radius, 0.0, 1e4, lo_open=True, unit="mm")
        if self.method == "iso23509-method0":
            check_range("offset_mm", self.offset, 0.0, 0.0, unit="mm")
            check_range("spiral_angle_deg", math.degrees(self.spiral_angle), 0.0, 70.0,
                        hi_open=True, unit="deg")
        else:
            check_range("offset_mm", self.offset, 1e-3 * de2, 0.25 * de2, unit="mm")
            check_range("spiral_angle_deg", math.degrees(self.spiral_angle), 0.0, 75.0,
                        lo_open=True, hi_open=True, unit="deg")
        for key, attr in (("pressure_angle_drive_deg", "pressure_angle_drive"),
                          ("pressure_angle_coast_deg", "pressure_angle_coast")):
            check_range(key, math.degrees(getattr(self, attr)), 0.0, 45.0, lo_open=True,
                        hi_open=True, unit="deg")
        check_range("limit_pressure_angle_factor", self.limit_pressure_angle_factor, 0.0, 1.0)
        khap = check_range("addendum_factor", self.addendum_factor, 0.0, 2.0, lo_open=True)
        check_range("dedendum_factor", self.dedendum_factor, khap, 3.0)
        check_range("profile_shift", self.profile_shift, -1.0, 1.0, lo_open=True, hi_open=True)
        for key, attr in (("wheel_addendum_angle_deg", "wheel_addendum_angle"),
                          ("wheel_dedendum_angle_deg", "wheel_dedendum_angle")):
            check_range(key, math.degrees(getattr(self, attr)), -10.0, 20.0, unit="deg")
        return self


def _file_defaults() -> dict:
    """{file key: (default in file units, unit)} of every optional ``[blank]`` key."""
    dflt = {f.name: f.default for f in fields(BlankInput)}
    out = {}
    for key, attr, kind in _KEYS:
        if key in _REQUIRED:
            continue
        v = dflt[attr]
        out[key] = (_deg_exact(v) if kind == "deg" else v, {"deg": "deg", "mm": "mm"}.get(kind, "-"))
    return out


#: defaults of the optional ``[blank]`` keys, file units: {key: (value, unit)}; a
#: design that relies on one gets it printed by ``gearjax example show`` and
#: ``gearjax blank`` (``defaults applied: ...``)
FILE_DEFAULTS = _file_defaults()


_META = ("z1", "z2", "method", "hand", "spiral_member", "taper")
jax.tree_util.register_dataclass(
    BlankInput, data_fields=[f.name for f in fields(BlankInput) if f.name not in _META],
    meta_fields=list(_META))


# ----------------------------------------------------------------------------- outputs
# (name, kind, description); kind "deg" = angle (rad inside), "mm", "-" dimensionless
OUTPUTS = [
    ("delta1", "deg", "pinion pitch angle"),
    ("delta2", "deg", "gear pitch angle"),
    ("delta_a1", "deg", "pinion face angle"),
    ("delta_a2", "deg", "gear face angle"),
    ("delta_f1", "deg", "pinion root angle"),
    ("delta_f2", "deg", "gear root angle"),
    ("theta_a1", "deg", "pinion addendum angle"),
    ("theta_a2", "deg", "gear addendum angle"),
    ("theta_f1", "deg", "pinion dedendum angle"),
    ("theta_f2", "deg", "gear dedendum angle"),
    ("beta_m1", "deg", "pinion mean spiral angle"),
    ("beta_m2", "deg", "gear mean spiral angle"),
    ("beta_e1", "deg", "pinion outer spiral angle"),
    ("beta_i1", "deg", "pinion inner spiral angle"),
    ("beta_e2", "deg", "gear outer spiral angle"),
    ("beta_i2", "deg", "gear inner spiral angle"),
    ("zeta_m", "deg", "pinion offset angle in the axial plane"),
    ("zeta_mp", "deg", "pinion offset angle in the pitch plane (= beta_m1 - beta_m2)"),
    ("alpha_lim", "deg", "limit pressure angle"),
    ("alpha_nD", "deg", "generated normal pressure angle, drive side"),
    ("alpha_nC", "deg", "generated normal pressure angle, coast side"),
    ("rho_lim", "mm", "limit radius of lengthwise curvature (= cutter radius, hypoid)"),
    ("Rm1", "mm", "pinion mean cone distance"),
    ("Rm2", "mm", "gear mean cone distance"),
    ("Re1", "mm", "pinion outer cone distance"),
    ("Re2", "mm", "gear outer cone distance"),
    ("Ri1", "mm", "pinion inner cone distance"),
    ("Ri2", "mm", "gear inner cone distance"),
    ("c_be2", "-", "face width factor (calculation point to outside / b2)"),
    ("b1", "mm", "pinion face width"),
    ("b2", "mm", "gear face width"),
    ("be1", "mm", "pinion face width, calculation point to outside"),
    ("bi1", "mm", "pinion face width, calculation point to inside"),
    ("a_p", "mm", "offset in the pitch plane"),
    ("m_mn", "mm", "mean normal module"),
    ("m_et2", "mm", "outer transverse module"),
    ("hmw", "mm", "mean working depth"),
    ("hm", "mm", "mean whole depth"),
    ("c", "mm", "clearance"),
    ("ham1", "mm", "pinion mean addendum"),
    ("ham2", "mm", "gear mean addendum"),
    ("hfm1", "mm", "pinion mean dedendum"),
    ("hfm2", "mm", "gear mean dedendum"),
    ("hae1", "mm", "pinion outer addendum"),
    ("hae2", "mm", "gear outer addendum"),
    ("hfe1", "mm", "pinion outer dedendum"),
    ("hfe2", "mm", "gear outer dedendum"),
    ("he1", "mm", "pinion outer whole depth"),
    ("he2", "mm", "gear outer whole depth"),
    ("hi1", "mm", "pinion inner whole depth"),
    ("hi2", "mm", "gear inner whole depth"),
    ("dm1", "mm", "pinion mean pitch diameter"),
    ("dm2", "mm", "gear mean pitch diameter"),
    ("de1", "mm", "pinion outer pitch diameter"),
    ("de2", "mm", "gear outer pitch diameter"),
    ("dae1", "mm", "pinion outside diameter"),
    ("dae2", "mm", "gear outside diameter"),
    ("dfe1", "mm", "pinion outer root diameter"),
    ("dfe2", "mm", "gear outer root diameter"),
    ("tz1", "mm", "pinion pitch apex beyond crossing point (ISO t_z1)"),
    ("tz2", "mm", "gear pitch apex beyond crossing point (ISO t_z2)"),
    ("tzm1", "mm", "crossing point to calculation point along pinion axis"),
    ("tzm2", "mm", "crossing point to calculation point along gear axis"),
    ("txo1", "mm", "pinion crossing point to crown (outer)"),
    ("txo2", "mm", "gear crossing point to crown (outer)"),
    ("tzF1", "mm", "pinion face apex beyond crossing point"),
    ("tzF2", "mm", "gear face apex beyond crossing point"),
    ("tzR1", "mm", "pinion root apex beyond crossing point"),
    ("tzR2", "mm", "gear root apex beyond crossing point"),
    ("theta1", "deg", "tangency route: pinion position angle of the pitch point"),
    ("theta2", "deg", "tangency route: gear position angle of the pitch point"),
    ("a1", "mm", "tangency route: pinion apex beyond crossing point (from the cones)"),
    ("a2", "mm", "tangency route: gear apex beyond crossing point (from the cones)"),
    ("machine_dV", "mm", "tangency route: pinion vertical wheel base E sin(theta2) - a1"),
    ("machine_dH", "mm", "tangency route: pinion horizontal wheel base E cos(theta2) + a2"),
    ("machine_cradle", "deg", "tangency route: pinion cradle angle theta2 +- 90 deg"),
    ("machine_tilt", "deg", "tangency route: cutter tilt asin(tan b1/tan a_lim); NaN: no solution"),
    ("machine_tilt_reciprocal", "deg", "gearjax reading asin(tan a_lim/tan b1)"),
    ("machine_X_G", "mm", "tangency route: gear machine centre to back (= a2)"),
    ("residual", "-", "root-finding residual (dimensionless)"),
    ("steps", "-", "Newton steps"),
    ("converged", "-", "1 if converged on the physical branch, else 0"),
]
_UNITS = {"deg": "deg", "mm": "mm", "-": ""}
# outputs that are legitimately non-finite: the tilt relation of [Tangent-cones] without a
# solution (NaN) and the limit curvature of a spiral-bevel pair (0/0, reported inf)
_MAY_BE_NONFINITE = ("machine_tilt", "rho_lim")
# outputs excluded from sensitivities (not smooth or not geometry)
_NO_SENS = ("machine_tilt", "residual", "steps", "converged")


def _to_table(self):
    """``[(name, value in display units, unit)]`` -- angles in degrees, lengths in mm."""
    rows = []
    for name, kind, _ in OUTPUTS:
        v = float(np.asarray(getattr(self, name)))
        rows.append((name, math.degrees(v) if kind == "deg" else v, _UNITS[kind]))
    return rows


def _to_dict(self):
    """JSON-ready dict ``{name: value}`` in display units (deg, mm) plus ``method``
    and ``units`` (``{name: unit}``); NaN becomes ``None``.  Keys: :data:`OUTPUTS`."""
    out = {"method": self.method}
    units = {}
    for name, value, unit in self.to_table():
        out[name] = None if not math.isfinite(value) else value
        units[name] = unit
    out["units"] = units
    return out


BlankData = make_dataclass(
    "BlankData",
    [(name, jax.Array) for name, _, _ in OUTPUTS] + [("method", str, field(default=""))],
    frozen=True,
    namespace={"to_table": _to_table, "to_dict": _to_dict},
)
BlankData.__module__ = __name__
BlankData.__doc__ = ("Blank geometry (mm, rad inside; ``to_table``/``to_dict`` in mm and "
                     "degrees).  Fields: " + "; ".join(f"``{n}`` {d}" for n, _, d in OUTPUTS)
                     + "; ``method`` (static).")
jax.tree_util.register_dataclass(BlankData, data_fields=[n for n, _, _ in OUTPUTS],
                                 meta_fields=["method"])


def blank_core(inp: BlankInput, ratio):
    """All outputs (dict, mm/rad) for ``inp`` with the ratio ``u`` given separately
    (a float, so it can be differentiated; ``z2 = u z1`` where the module enters)."""
    u = ratio
    Sigma, E = inp.shaft_angle, inp.offset
    de2, b2, beta, rc0 = (inp.gear_outer_pitch_diameter, inp.gear_face_width,
                          inp.spiral_angle, inp.cutter_radius)
    z = 0.0 * (u + Sigma + E + de2 + b2 + beta + rc0)
    if inp.method == "iso23509-method0":
        pc = iso23509.method0_pitch_cones(u, Sigma, de2, b2, beta)
        rule = "method0"
    elif inp.method == "iso23509-method1":
        pc = iso23509.method1_pitch_cones(u, Sigma, E, de2, b2, beta, rc0)
        rule = "method1"
    else:
        sol = pitch_cones.solve_pitch_cones(u, Sigma, E, de2, b2, beta, rc0,
                                            spiral_member=inp.spiral_member, throw=False)
        pc = dict(delta1=sol.delta1, delta2=sol.delta2, Rm1=sol.R1, Rm2=sol.R2,
                  beta_m1=sol.beta1, beta_m2=sol.beta2, c_be2=0.5 + z, rho_lim=sol.rho_lim,
                  residual=sol.residual, steps=sol.steps, converged=sol.converged)
        rule = "method1"
    gd = iso23509.gear_dimensions(
        pc, z1=float(inp.z1), u=u, Sigma=Sigma, a=E, b2=b2, rc0=rc0,
        alpha_dD=inp.pressure_angle_drive, alpha_dC=inp.pressure_angle_coast,
        f_alim=inp.limit_pressure_angle_factor, khap=inp.addendum_factor,
        khfp=inp.dedendum_factor, xhm1=inp.profile_shift, taper=inp.taper,
        theta_a2=inp.wheel_addendum_angle, theta_f2=inp.wheel_dedendum_angle,
        pinion_rule=rule)
    if inp.method == "iso23509-method0":
        theta1, theta2, a1, a2 = -0.5 * jnp.pi + z, 0.5 * jnp.pi + z, z, z
    else:
        geo = pitch_cones.cone_tangency(pc["delta1"], pc["delta2"], Sigma, E, pc["Rm2"])
        theta1, theta2, a1, a2 = geo["theta1"], geo["theta2"], geo["a1"], geo["a2"]
    sol_like = pitch_cones.PitchConeSolution(
        delta1=pc["delta1"], delta2=pc["delta2"], R1=pc["Rm1"], R2=pc["Rm2"], r1=z, r2=z,
        theta1=theta1, theta2=theta2, a1=a1, a2=a2, zeta=gd["zeta_mp"], beta1=pc["beta_m1"],
        beta2=pc["beta_m2"], alpha_lim=gd["alpha_lim"], rho_lim=pc["rho_lim"],
        residual=pc["residual"], steps=pc["steps"], converged=pc["converged"])
    ms = pitch_cones.pinion_machine_settings(sol_like, E, inp.hand)
    out = dict(gd)
    out.update(delta1=pc["delta1"], delta2=pc["delta2"], beta_m1=pc["beta_m1"],
               beta_m2=pc["beta_m2"], rho_lim=pc["rho_lim"], Rm1=pc["Rm1"], Rm2=pc["Rm2"],
               c_be2=pc["c_be2"], b2=b2 + z, a_p=gd["ap"], m_et2=gd["met2"],
               theta1=theta1, theta2=theta2, a1=a1, a2=a2,
               machine_dV=ms["dV"], machine_dH=ms["dH"], machine_cradle=ms["cradle"],
               machine_tilt=ms["tilt"], machine_tilt_reciprocal=ms["tilt_reciprocal"],
               machine_X_G=ms["X_G"], residual=pc["residual"] + z,
               steps=jnp.asarray(pc["steps"], dtype=float),
               converged=jnp.asarray(pc["converged"], dtype=float))
    return {name: jnp.asarray(out[name], dtype=float) for name, _, _ in OUTPUTS}


_core_jit = jax.jit(blank_core)


def blank_geometry(inp: BlankInput, *, throw: bool = True):
    """Blank geometry for ``inp`` as a :class:`BlankData` (mm, rad).

    Pure and jit/jacfwd/vmap-friendly (``jax.jit(blank_geometry)`` works; the
    method and tooth numbers are static).  Nothing is validated inside; use
    :meth:`BlankInput.from_dict` or :meth:`BlankInput.validate` for designer input.
    With ``throw=True`` and concrete values a non-converged root finding raises
    :class:`gearjax.errors.ConvergenceError`, and an undefined blank (non-finite
    outputs, e.g. a cutter too small for the face width and spiral angle, ISO 23509
    (183)) raises ``ValueError``; otherwise check ``converged`` (1/0) and the values.
    """
    out = _core_jit(inp, inp.z2 / inp.z1)
    data = BlankData(**out, method=inp.method)
    conv = data.converged
    if throw and not isinstance(conv, jax.core.Tracer):
        require_converged(np.asarray(conv) > 0.5, f"blank geometry ({inp.method})",
                          data.residual)
        bad = [n for n, _, _ in OUTPUTS if n not in _MAY_BE_NONFINITE
               and not np.all(np.isfinite(np.asarray(getattr(data, n))))]
        if bad:
            raise ValueError(
                f"cutter_radius_mm = {float(inp.cutter_radius):g} gives an undefined blank "
                f"(non-finite {', '.join(bad)}): a circular tooth trace of this radius cannot "
                f"span the face width at this spiral angle (ISO 23509 (183)-(194) need "
                f"|sin beta| <= 1); use a larger cutter")
    return data


SENSITIVITY_INPUTS = ("offset", "ratio", "gear_outer_pitch_diameter", "gear_face_width",
                      "cutter_radius", "spiral_angle")


def _sens_values(inp: BlankInput, x, names):
    """Outputs ``names`` as a vector for the continuous design vector
    ``x = (offset, ratio, gear_outer_pitch_diameter, gear_face_width, cutter_radius,
    spiral_angle)``; the other fields of ``inp`` are held."""
    new = dataclasses.replace(inp, offset=x[0], gear_outer_pitch_diameter=x[2],
                              gear_face_width=x[3], cutter_radius=x[4], spiral_angle=x[5])
    out = blank_core(new, x[1])
    return jnp.stack([out[n] for n in names])


# compiled once per (method, tooth numbers, output list); reused across designs
_sens_values_jit = jax.jit(_sens_values, static_argnames=("names",))
_sens_jac_jit = jax.jit(jax.jacfwd(_sens_values, argnums=1), static_argnames=("names",))


def blank_sensitivity(inp: BlankInput, outputs=None) -> dict:
    """Jacobian of the blank outputs w.r.t. the design inputs by ``jax.jacfwd``.

    Inputs (columns, internal units): ``offset`` E (mm), ``ratio`` u = z2/z1 as a
    continuous quantity (z1 held), ``gear_outer_pitch_diameter`` (mm),
    ``gear_face_width`` (mm), ``cutter_radius`` (mm), ``spiral_angle`` (rad).
    Outputs (rows): ``outputs`` (names from :data:`OUTPUTS`), default all smooth
    ones (everything but ``machine_tilt``, ``residual``, ``steps``, ``converged``).
    Derivatives through the Newton solves come from the implicit function theorem.
    For Method 0 the offset column is the derivative at E = 0 of the Method-0
    formulae, which do not contain E (zero); use a hypoid method for offset effects.

    Returns ``{"inputs": [...], "outputs": [...], "jacobian": ndarray (n_out, n_in),
    "values": ndarray (n_out,)}`` in mm and rad.
    """
    names = tuple(n for n, _, _ in OUTPUTS if n not in _NO_SENS) if outputs is None \
        else tuple(outputs)
    x0 = jnp.array([inp.offset, inp.z2 / inp.z1, inp.gear_outer_pitch_diameter,
                    inp.gear_face_width, inp.cutter_radius, inp.spiral_angle], dtype=float)
    J = _sens_jac_jit(inp, x0, names=names)
    return {"inputs": list(SENSITIVITY_INPUTS), "outputs": list(names),
            "jacobian": np.asarray(J), "values": np.asarray(_sens_values_jit(inp, x0, names=names))}
