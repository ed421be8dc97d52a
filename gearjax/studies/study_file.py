"""Study files: what ``gearjax optimize STUDY.toml`` optimises, read and validated.

A study names a design, the design fields it varies, an objective and constraints
made of named quantities (:data:`gearjax.studies.quantities.QUANTITIES`), the
scenarios they are evaluated at, and the optimiser.  Schema (docs/optimize.md has the
full text with examples)::

    [study]        name (required), description, design ("example:NAME" or a path
                   relative to the study file; required), side ("drive" | "coast")
    [operating]    torque_Nm, pinion_rpm, oil (a known oil), sigma_um -- required when a
                   loaded quantity is used; compliance ("weber" | "iso6336")
    [scenarios]    optional; torque_Nm, pinion_rpm, dE_mm, dP_mm, dG_mm, dSigma_deg as a
                   number or a list: every combination is a scenario (one vmapped run);
                   a line-contact study: torque_Nm, pinion_rpm, f_ma_um
    [tca]          optional TCA grid: steps_per_pitch, half_pitches, n_pairs
    [line]         optional, a line-contact study: positions (per base pitch, default
                   24), slices (face-width slices, default 12)
    [kinematics]   optional, a kinematics study: flank ("convex" | "concave"), grid =
                   [depth, face] points (default [9, 7]); no [scenarios]/[operating]
    [[variables]]  field (a field of the design's pair, ``gearjax optimize STUDY
                   --fields`` lists them; a line-contact study: a micro-geometry field
                   ``microgeometry.TABLE.KEY`` as in the design file's tables,
                   :mod:`gearjax.studies.line_route`), lower/upper (absolute) or change = [lo, hi]
                   (relative to the design's value); unit "" (the field's own: mm, rad,
                   -) or "deg" for a field in rad; scale (default (upper - lower)/2)
    [[objective]]  quantity, weight (> 0), sense ("minimize" | "maximize"),
                   over ("mean" | "max": the scenario reduction; "max" is smooth),
                   scale (default |value at the start|)
    [[constraints]] quantity, lower and/or upper (every scenario), scale (default
                   |bound|, 1 for a bound 0)
    [optimizer]    method ("augmented_lagrangian" | "slsqp"), max_iterations,
                   tolerance (on the scaled KKT measures), starts (multi-start), seed
    [sweep]        optional, for ``gearjax sweep``: method ("random": Latin hypercube |
                   "grid"), samples (random), points (grid, per variable), seed, chunk

**Routes.**  The quantities of a study are of one route (``Quantity.route``): the
unloaded TCA and its point-contact loaded chain (``"tca"``), or the loaded line contact
of an involute pair with micro-geometry (``"line"``: the ``line_*`` quantities,
micro-geometry variables, the ``f_ma_um`` scenarios), or the eigenfunction kinematics
of a hypoid flank (``"kinematics"``: the ``kin_*`` quantities, the cutter settings as
variables, one implicit scenario, :mod:`gearjax.studies.kinematics_route`); a study
that mixes them, or whose
variables do not belong to its route, is refused naming the entry.

Every entry is checked before any work; a bad one is a one-line ``ValueError`` naming
it (``[[variables]] 2: field 'pair.x3' is not a field of ...``).  Fields are checked
against the design when the study is set up (:mod:`gearjax.studies.study_run`), here
only their form.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from gearjax.io.toml import (check_integer, check_keys, check_number, check_string, is_number,
                             read_toml, require_key)
from gearjax.studies.quantities import QUANTITIES, uses_mask

__all__ = ["Variable", "Term", "Constraint", "Study", "read_study", "list_studies",
           "study_path", "check_quantities", "SCENARIO_KEYS", "LINE_SCENARIO_KEYS", "METHODS",
           "LINE_DEFAULTS"]

#: scenario key -> unit (misalignment keys in mm and degrees, as ``--misalign``)
SCENARIO_KEYS = {"torque_Nm": "N m", "pinion_rpm": "rpm", "dE_mm": "mm", "dP_mm": "mm",
                 "dG_mm": "mm", "dSigma_deg": "deg"}
#: scenario key -> unit of a line-contact study (``f_ma_um``: the mesh misalignment of
#: ISO 6336-1 across the face width, as ``gearjax loaded --misalignment-um``)
LINE_SCENARIO_KEYS = {"torque_Nm": "N m", "pinion_rpm": "rpm", "f_ma_um": "um"}
#: the ``[line]`` table's keys and defaults (mesh positions per base pitch, face slices)
LINE_DEFAULTS = {"positions": 24, "slices": 12}
METHODS = ("augmented_lagrangian", "slsqp")
SWEEP_METHODS = ("random", "grid")
#: the ``[sweep]`` table's keys and defaults (``gearjax sweep``)
SWEEP_DEFAULTS = {"method": "random", "points": 5, "samples": 64, "seed": 0, "chunk": 16}
_OPERATING = {"torque_Nm", "pinion_rpm", "oil", "sigma_um", "compliance", "edge_softening_mm"}
_TCA = {"steps_per_pitch", "half_pitches", "n_pairs"}


@dataclass(frozen=True)
class Variable:
    """A design field varied by the study: absolute bounds (the field's units) or a
    change relative to the design's value, and the scale of one optimiser unit."""

    field: str
    lower: float | None = None
    upper: float | None = None
    change: tuple | None = None
    unit: str = ""
    scale: float | None = None

    @property
    def factor(self) -> float:
        """Field units per file unit (pi/180 for ``unit = "deg"``)."""
        return math.pi / 180.0 if self.unit == "deg" else 1.0

    def bounds(self, x0: float) -> tuple:
        """``(lower, upper)`` in the field's units around its start value ``x0``."""
        if self.change is not None:
            return x0 + self.change[0] * self.factor, x0 + self.change[1] * self.factor
        return self.lower * self.factor, self.upper * self.factor


@dataclass(frozen=True)
class Term:
    quantity: str
    weight: float = 1.0
    sense: str = "minimize"
    over: str = "mean"
    scale: float | None = None


@dataclass(frozen=True)
class Constraint:
    quantity: str
    lower: float | None = None
    upper: float | None = None
    scale: float | None = None
    added: bool = False      # added by the study (the fixed mask's margin), not the file


@dataclass(frozen=True)
class Study:
    """A validated study file (module docstring)."""

    name: str
    design: str
    side: str
    variables: tuple
    objective: tuple
    constraints: tuple
    description: str = ""
    operating: dict = field(default_factory=dict)
    scenarios: dict = field(default_factory=dict)
    tca: dict = field(default_factory=dict)
    method: str = "augmented_lagrangian"
    max_iterations: int = 30
    tolerance: float = 1e-4
    starts: int = 1
    seed: int = 0
    source: str = ""
    #: quantities evaluated and reported but in neither the objective nor a constraint
    reported: tuple = ()
    #: the ``[sweep]`` table (``gearjax sweep``): method, points, samples, seed, chunk
    sweep: dict = field(default_factory=dict)
    #: the ``[line]`` table of a line-contact study (positions, slices; defaults filled)
    line: dict = field(default_factory=dict)
    #: the ``[kinematics]`` table of a kinematics study (flank, grid; defaults filled)
    kinematics: dict = field(default_factory=dict)

    @property
    def route(self) -> str:
        """``"tca"``, ``"line"`` or ``"kinematics"`` (module docstring)."""
        from gearjax.studies.quantities import route_of
        return route_of([t.quantity for t in self.objective]
                        + [c.quantity for c in self.constraints])

    @property
    def quantities(self) -> list:
        """The quantities the study evaluates (objective, constraints, then those only
        reported)."""
        out = []
        for q in ([t.quantity for t in self.objective] + [c.quantity for c in self.constraints]
                  + list(self.reported)):
            if q not in out:
                out.append(q)
        return out


def list_studies() -> list[str]:
    """Names of the packaged studies (``example:NAME`` for ``gearjax optimize``)."""
    root = resources.files("gearjax") / "examples" / "studies"
    return sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".toml"))


def study_path(name: str):
    """Path of a packaged study; ValueError naming the known ones."""
    names = list_studies()
    if name not in names:
        raise ValueError(f"unknown example study {name!r} (known: {', '.join(names)})")
    return resources.files("gearjax") / "examples" / "studies" / f"{name}.toml"


def check_quantities(names, where: str, operating: dict) -> None:
    """Each of ``names`` a known quantity, and the operating point's keys given when one
    needs the loaded chain (one-line ValueError naming ``where`` and the entry)."""
    for q in names:
        if q not in QUANTITIES:
            raise ValueError(f"{where}: unknown quantity {q!r} (known: {', '.join(QUANTITIES)})")
    loaded = [q for q in names if QUANTITIES[q].loaded]
    missing = [k for k in ("torque_Nm", "pinion_rpm", "oil", "sigma_um") if k not in operating]
    if loaded and missing:
        raise ValueError(f"{where}: the loaded quantity {loaded[0]!r} needs the operating "
                         f"point: {missing[0]} is missing")


def _entry_messages(fn):
    """Entry readers' errors as ``[[variables]] 2: lower = nan ...``: the table helpers of
    :mod:`gearjax.io.toml` write ``[where] key``, which for an array entry would read
    ``[[[variables]] 2] key``."""
    import functools
    import re

    @functools.wraps(fn)
    def read(i, e):
        try:
            return fn(i, e)
        except ValueError as exc:
            msg = re.sub(r"in \[(\[\[\w+\]\] \d+)\]", r"in \1", str(exc))
            msg = re.sub(r"\[(\[\[\w+\]\] \d+)\]", r"\1:", msg)
            msg = re.sub(r"'\[\[\w+\]\] \d+\.", "'", msg)
            raise ValueError(msg.replace("::", ":")) from None
    return read


def _entries(data, key) -> list:
    v = data.get(key, [])
    if not isinstance(v, list) or not all(isinstance(e, dict) for e in v):
        raise ValueError(f"[[{key}]] must be an array of tables ([[{key}]] ... entries)")
    return v


def _quantity(where, e) -> str:
    q = check_string(where, "quantity", require_key(where, e, "quantity"))
    if q not in QUANTITIES:
        raise ValueError(f"{where}: unknown quantity {q!r} (known: {', '.join(QUANTITIES)})")
    return q


def _scale(where, e):
    if "scale" not in e:
        return None
    s = check_number(where, "scale", e["scale"])
    if s <= 0.0:
        raise ValueError(f"{where}: scale = {s:g} must be > 0")
    return s


@_entry_messages
def _variable(i, e) -> Variable:
    w = f"[[variables]] {i}"
    check_keys(w, e, {"field", "lower", "upper", "change", "unit", "scale"})
    name = check_string(w, "field", require_key(w, e, "field"))
    unit = check_string(w, "unit", e.get("unit", ""), ("", "deg"))
    has_abs = "lower" in e or "upper" in e
    if has_abs == ("change" in e):
        raise ValueError(f"{w} ({name}): give either lower and upper (absolute) or change = "
                         "[lo, hi] (relative to the design's value)")
    lo = hi = change = None
    if has_abs:
        lo = check_number(w, "lower", require_key(w, e, "lower"))
        hi = check_number(w, "upper", require_key(w, e, "upper"))
        empty = not lo < hi
    else:
        c = e["change"]
        if not (isinstance(c, list) and len(c) == 2 and all(is_number(v) for v in c)):
            raise ValueError(f"{w} ({name}): change = {c!r} must be two numbers [lo, hi]")
        change = (check_number(w, "change[0]", c[0]), check_number(w, "change[1]", c[1]))
        empty = not change[0] <= 0.0 <= change[1] or not change[0] < change[1]
    if empty:
        what = f"[{lo:g}, {hi:g}]" if has_abs else f"change {list(change)}"
        raise ValueError(f"{w} ({name}): empty or invalid bounds {what} (need lower < upper"
                         + ("" if has_abs else ", and the range must contain 0") + ")")
    return Variable(name, lo, hi, change, unit, _scale(w, e))


@_entry_messages
def _term(i, e) -> Term:
    w = f"[[objective]] {i}"
    check_keys(w, e, {"quantity", "weight", "sense", "over", "scale"})
    q = _quantity(w, e)
    wt = check_number(w, "weight", e.get("weight", 1.0))
    if wt <= 0.0:
        raise ValueError(f"{w} ({q}): weight = {wt:g} must be > 0 (use sense = 'maximize')")
    return Term(q, wt, check_string(w, "sense", e.get("sense", "minimize"),
                                    ("minimize", "maximize")),
                check_string(w, "over", e.get("over", "mean"), ("mean", "max")), _scale(w, e))


@_entry_messages
def _constraint(i, e) -> Constraint:
    w = f"[[constraints]] {i}"
    check_keys(w, e, {"quantity", "lower", "upper", "scale"})
    q = _quantity(w, e)
    lo = check_number(w, "lower", e["lower"]) if "lower" in e else None
    hi = check_number(w, "upper", e["upper"]) if "upper" in e else None
    if lo is None and hi is None:
        raise ValueError(f"{w} ({q}): give lower, upper or both")
    if lo is not None and hi is not None and not lo < hi:
        raise ValueError(f"{w} ({q}): empty range [{lo:g}, {hi:g}] (need lower < upper)")
    return Constraint(q, lo, hi, _scale(w, e))


def _operating(op) -> dict:
    """The ``[operating]`` table with every value checked (type, allowed names, ranges of
    the softening; torque and speed against their ranges when the study is set up)."""
    from gearjax.errors import check_range
    from gearjax.loading import COMPLIANCE_MODELS
    from gearjax.tribology import OILS
    check_keys("operating", op, _OPERATING)
    out = {}
    for k, v in op.items():
        if k == "oil":
            out[k] = check_string("operating", k, v, OILS)
        elif k == "compliance":
            out[k] = check_string("operating", k, v, COMPLIANCE_MODELS)
        else:
            out[k] = check_number("operating", k, v)
    if "edge_softening_mm" in out:
        try:
            check_range("edge_softening_mm", out["edge_softening_mm"], 0.0, 10.0, unit="mm")
        except ValueError as exc:
            raise ValueError(f"[operating] {exc}") from None
    if "sigma_um" in out and not out["sigma_um"] > 0.0:
        raise ValueError(f"[operating] sigma_um = {out['sigma_um']:g} must be > 0 (um)")
    return out


def _scenarios(sc, route: str) -> dict:
    keys = LINE_SCENARIO_KEYS if route == "line" else SCENARIO_KEYS
    other = set(SCENARIO_KEYS if route == "line" else LINE_SCENARIO_KEYS) - set(keys)
    for k in sc:
        if k in other:
            raise ValueError(f"[scenarios] {k}: a scenario key of the "
                             f"{'TCA' if route == 'line' else 'line-contact'} route; this "
                             f"study's quantities are of the {route} route (keys: "
                             f"{', '.join(keys)})")
    check_keys("scenarios", sc, set(keys))
    out = {}
    for k, v in sc.items():
        vals = v if isinstance(v, list) else [v]
        if not vals:
            raise ValueError(f"[scenarios] {k} = [] is empty (give a number or a list)")
        out[k] = tuple(check_number("scenarios", k, x, keys[k]) for x in vals)
    return out


def _one_route(objective, constraints) -> str:
    """The route of the study's quantities; one line naming the first entry whose route
    differs from the objective's first term's (module docstring)."""
    from gearjax.studies.quantities import QUANTITIES
    entries = ([(f"[[objective]] {i + 1}", t.quantity) for i, t in enumerate(objective)]
               + [(f"[[constraints]] {i + 1}", c.quantity) for i, c in enumerate(constraints)])
    first = QUANTITIES[entries[0][1]].route
    for where, q in entries[1:]:
        if QUANTITIES[q].route != first:
            names = {"tca": "TCA", "line": "loaded line-contact",
                     "kinematics": "eigenfunction kinematics"}
            raise ValueError(f"{where}: quantity {q!r} is of the {names[QUANTITIES[q].route]} "
                             f"route, [[objective]] 1 ({entries[0][1]!r}) of the "
                             f"{names[first]} route: a study uses one route")
    return first


def _check_variable_routes(variables, route: str, side: str) -> None:
    """Micro-geometry fields in a line-contact study only, and only those there (their
    form checked: :func:`gearjax.studies.line_route.micro_field`); the cutter settings
    in a kinematics study only, and only those there
    (:func:`gearjax.studies.kinematics_route.check_field`)."""
    from gearjax.studies.kinematics_route import KIN_FIELDS, check_field
    from gearjax.studies.line_route import MICRO_PREFIX, micro_field
    for i, v in enumerate(variables):
        w = f"[[variables]] {i + 1}"
        if route == "kinematics" or v.field in KIN_FIELDS:
            if route != "kinematics":
                raise ValueError(f"{w}: field {v.field!r} is a cutter setting of the "
                                 "eigenfunction kinematics: use its quantities (kin_*, "
                                 "gearjax optimize --quantities)")
            try:
                check_field(v.field, v.unit)
            except ValueError as exc:
                raise ValueError(f"{w}: {exc}") from None
            continue
        micro = v.field.startswith(MICRO_PREFIX)
        if micro and route != "line":
            raise ValueError(f"{w}: the micro-geometry field {v.field!r} is analysed by the "
                             "loaded line contact: use its quantities (line_*, gearjax "
                             "optimize --quantities)")
        if route == "line" and not micro:
            raise ValueError(f"{w}: field {v.field!r}: a line-contact study varies "
                             f"micro-geometry fields ({MICRO_PREFIX}TABLE.KEY)")
        if micro:
            try:
                micro_field(v.field, side)
            except ValueError as exc:
                raise ValueError(f"{w}: {exc}") from None
            if v.unit:
                raise ValueError(f"{w} ({v.field}): unit = {v.unit!r}: a micro-geometry "
                                 "field is in the unit of its key (um or mm)")


def _line_table(data, route: str, op: dict, scenarios: dict) -> dict:
    """The ``[line]`` table (defaults :data:`LINE_DEFAULTS`); a line-contact study needs a
    torque and takes no ``[tca]`` table nor edge softening; a TCA study no ``[line]``."""
    if route != "line":
        if "line" in data:
            raise ValueError("[line]: the line-contact model's options, but the study's "
                             f"quantities are of the {route} route")
        return {}
    if "tca" in data:
        raise ValueError("[tca]: the TCA grid, but the study's quantities are of the "
                         "line-contact route (its options: [line] positions, slices)")
    if "edge_softening_mm" in op:
        raise ValueError("[operating] edge_softening_mm: the soft active set of the TCA "
                         "route's loaded chain; the line contact has none")
    if "torque_Nm" not in op and "torque_Nm" not in scenarios:
        raise ValueError("[operating] torque_Nm: a line-contact study needs the torque "
                         "([operating] torque_Nm or [scenarios] torque_Nm)")
    ln = data.get("line", {})
    check_keys("line", ln, set(LINE_DEFAULTS) | {"coupling_length_mm"})
    out = {k: check_integer("line", k, ln.get(k, d), 4 if k == "positions" else 1)
           for k, d in LINE_DEFAULTS.items()}
    # the coupling of the slices along the face (mm; 0: Winkler), docs/microgeometry.md
    from gearjax.errors import check_range
    from gearjax.gears.involute.loaded_lines import COUPLING_LENGTH_RANGE_MM
    lam = check_number("line", "coupling_length_mm", ln.get("coupling_length_mm", 0.0))
    try:
        out["coupling_length_mm"] = check_range("coupling_length_mm", lam,
                                                *COUPLING_LENGTH_RANGE_MM, unit="mm")
    except ValueError as exc:
        raise ValueError(f"[line] {exc}") from None
    return out


def _kinematics_table(data, route: str) -> dict:
    """The ``[kinematics]`` table (defaults
    :data:`gearjax.studies.kinematics_route.KIN_DEFAULTS`); a kinematics study has one
    implicit scenario and no operating point, TCA or line-contact options."""
    from gearjax.studies.kinematics_route import KIN_DEFAULTS
    if route != "kinematics":
        if "kinematics" in data:
            raise ValueError("[kinematics]: the eigenfunction model's options, but the study's "
                             f"quantities are of the {route} route")
        return {}
    for key in ("scenarios", "operating", "tca", "line"):
        if key in data:
            raise ValueError(f"[{key}]: a kinematics study (kin_* quantities) has one "
                             "implicit scenario and no operating point; remove the table")
    kt = data.get("kinematics", {})
    check_keys("kinematics", kt, set(KIN_DEFAULTS))
    flank = check_string("kinematics", "flank", kt.get("flank", KIN_DEFAULTS["flank"]),
                         ("convex", "concave"))
    grid = kt.get("grid", list(KIN_DEFAULTS["grid"]))
    if not (isinstance(grid, list) and len(grid) == 2):
        raise ValueError(f"[kinematics] grid = {grid!r} must be [depth, face] points")
    g = tuple(check_integer("kinematics", f"grid[{i}]", x, 3) for i, x in enumerate(grid))
    if max(g) > 201:
        raise ValueError(f"[kinematics] grid = {list(g)}: at most 201 points each way")
    return {"flank": flank, "grid": g}


def _design_source(design: str, base) -> str:
    if design.startswith("example:") or base is None or os.path.isabs(design):
        return design
    return str(Path(base).parent / design)


def read_study(source) -> Study:
    """Read and validate a study file (a path, or ``example:NAME`` for a packaged study)."""
    if isinstance(source, str) and source.startswith("example:"):
        path, base = study_path(source[len("example:"):]), None
    else:
        path, base = source, source
    try:
        data = read_toml(path)
    except ValueError as exc:      # the reader speaks of design files
        raise ValueError(str(exc).replace("design file", "study file")) from None
    check_keys("", data, {"study", "operating", "scenarios", "tca", "variables", "objective",
                          "constraints", "optimizer", "sweep", "line", "kinematics"})
    st = require_key("", data, "study")
    check_keys("study", st, {"name", "description", "design", "side"})
    name = check_string("study", "name", require_key("study", st, "name"))
    if not name or not all(c.isalnum() or c in "_-" for c in name):
        raise ValueError(f"[study] name = {name!r} must be a non-empty word of letters, digits, "
                         "'_' and '-' (it names the output files)")
    design = _design_source(check_string("study", "design", require_key("study", st, "design")),
                            base)
    side = check_string("study", "side", st.get("side", "drive"), ("drive", "coast"))
    variables = tuple(_variable(i + 1, e) for i, e in enumerate(_entries(data, "variables")))
    if not variables:
        raise ValueError("the study has no [[variables]] (name at least one design field)")
    fields = [v.field for v in variables]
    dup = sorted({f for f in fields if fields.count(f) > 1})
    if dup:
        raise ValueError(f"[[variables]]: field {dup[0]!r} is given more than once")
    objective = tuple(_term(i + 1, e) for i, e in enumerate(_entries(data, "objective")))
    if not objective:
        raise ValueError("the study has no [[objective]] term (name at least one quantity)")
    constraints = [_constraint(i + 1, e) for i, e in enumerate(_entries(data, "constraints"))]
    route = _one_route(objective, constraints)
    _check_variable_routes(variables, route, side)
    kinematics = _kinematics_table(data, route)
    names = [t.quantity for t in objective] + [c.quantity for c in constraints]
    if uses_mask(names) and not any(c.quantity == "min_margin_mm" and c.lower is not None
                                    for c in constraints):
        # the path quantities' fixed mask stays on the flank (gearjax.studies.quantities)
        constraints.append(Constraint("min_margin_mm", 0.0, None, 1.0, added=True))
    op = _operating(data.get("operating", {}))
    check_quantities(names, "[operating]", op)
    scenarios = _scenarios(data.get("scenarios", {}), route)
    line = _line_table(data, route, op, scenarios)
    opt = data.get("optimizer", {})
    check_keys("optimizer", opt, {"method", "max_iterations", "tolerance", "starts", "seed"})
    method = check_string("optimizer", "method", opt.get("method", METHODS[0]), METHODS)
    max_it = check_integer("optimizer", "max_iterations", opt.get("max_iterations", 30), 1)
    tol = check_number("optimizer", "tolerance", opt.get("tolerance", 1e-4))
    if not 0.0 < tol < 1.0:
        raise ValueError(f"[optimizer] tolerance = {tol:g} must be in (0, 1)")
    starts = check_integer("optimizer", "starts", opt.get("starts", 1), 1)
    if method == "slsqp" and starts > 1:
        raise ValueError(f"[optimizer] starts = {starts}: the slsqp method runs one start "
                         "(multi-start is for augmented_lagrangian)")
    tca = data.get("tca", {})
    check_keys("tca", tca, _TCA)
    return Study(name=name, design=design, side=side, variables=variables,
                 objective=objective, constraints=tuple(constraints),
                 description=check_string("study", "description", st.get("description", "")),
                 operating=op, scenarios=scenarios, line=line, kinematics=kinematics,
                 tca={k: check_number("tca", k, v) for k, v in tca.items()}, method=method,
                 max_iterations=max_it, tolerance=tol, starts=starts,
                 seed=check_integer("optimizer", "seed", opt.get("seed", 0), 0),
                 source=str(source), sweep=_sweep(data.get("sweep", {})))


def _sweep(sw) -> dict:
    """The ``[sweep]`` table: ``method`` ("random": a Latin hypercube of ``samples``
    designs, or "grid": ``points`` values per variable), ``seed``, ``chunk`` (designs
    per batch; rounded up to a multiple of the device count)."""
    check_keys("sweep", sw, set(SWEEP_DEFAULTS))
    out = dict(SWEEP_DEFAULTS)
    out["method"] = check_string("sweep", "method", sw.get("method", "random"), SWEEP_METHODS)
    out["points"] = check_integer("sweep", "points", sw.get("points", out["points"]), 2)
    out["samples"] = check_integer("sweep", "samples", sw.get("samples", out["samples"]), 1)
    out["seed"] = check_integer("sweep", "seed", sw.get("seed", out["seed"]), 0)
    out["chunk"] = check_integer("sweep", "chunk", sw.get("chunk", out["chunk"]), 1)
    return out
