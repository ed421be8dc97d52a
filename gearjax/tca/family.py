"""A gear family as data, and the one TCA driver every ported family runs through.

A family says *what* its pair is -- flanks, mounting, flank boundaries, edges,
reference contact, summary -- by implementing :class:`GearFamily`; the driver here
says *how* a TCA is run, once for every family: the grid of pinion angles, the
continued contact solve (:func:`gearjax.tca.path.contact_path`), the edge contacts
(:func:`gearjax.tca.edge_contact.face_end_contact`), the consecutive tooth pairs and the
TE envelope (:func:`gearjax.tca.multi_pair.multi_pair`), the rolling/sliding kinematics
(:func:`gearjax.tca.result.contact_kinematics`) and the :class:`TCAResult`.  A
concrete TCA runs as two compiled programs -- :func:`tca_surface` (reference, grid,
surface contact, margins) and :func:`tca_finish` (edge contacts, tooth pairs,
kinematics) -- compiled side by side (:mod:`gearjax.compile_ahead`); the pair of them
per family class and static option set serves both sides and every design of the
family (the family object is a static argument; the pair a pytree).

**Side convention** (the same in every ported family): the user names a side
``"drive"`` or ``"coast"``; inside a program it is the traced boolean ``drive`` (True
on the drive side), so that both sides share one program.  Which sense of rotation a
side's flank pushes the gear for is the family's :meth:`GearFamily.forward`: True
where the pinion flank pushes the gear for increasing ``phi1``, so that the TE
envelope is the maximum over the tooth pairs (the ``drive`` argument of
:func:`~gearjax.tca.edge_contact.face_end_contact` and
:func:`~gearjax.tca.multi_pair.multi_pair`).

**Options** (same names, meaning and checks in every family): ``steps_per_pitch``,
``half_pitches``, ``n_pairs`` (defaults: :attr:`GearFamily.defaults`), ``approach``
(mm, Hertz approach of the contact ellipse), ``kinematics`` (default True),
``face_ends`` (default True: solve the edge contacts), ``throw`` (``run`` only).
``line_contact`` is accepted where the family supports it (:attr:`GearFamily.
line_contact_modes`) and refused in one line elsewhere; an unknown option is refused
in one line naming it; an option given as None takes the family's default.

Every family registers a :class:`DriverAdapter` of its :class:`GearFamily`
(docs/architecture.md, "Where a new gear family goes").
"""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.compile_ahead import CompileAhead, call, first_time, prefetch
from gearjax.newton import with_value
from gearjax.tca.edge_contact import face_end_contact
from gearjax.tca.multi_pair import multi_pair
from gearjax.tca.path import (DEFAULT_APPROACH, check_on_flank_converged, check_tca_options,
                              contact_path, pinion_angle_grid)
from gearjax.tca.assembly import Misalignment
from gearjax.tca.result import TCAResult, check_side, contact_kinematics, strong_float64

__all__ = ["GearFamily", "DriverAdapter", "tca_parts", "tca_surface", "tca_finish",
           "sensitivity_table", "OPTION_NAMES"]

#: the TCA options every family accepts (``line_contact`` only where supported)
OPTION_NAMES = ("steps_per_pitch", "half_pitches", "n_pairs", "approach", "kinematics",
                "face_ends", "line_contact")


class GearFamily:
    """What a gear family provides to the driver (subclass and override; stateless,
    hashable: the family object is a static argument of the compiled programs).

    ``pair`` below is the pytree a compiled program runs on (e.g. a dataclass of
    floats); ``setup`` the concrete set-up of a design for one side (:meth:`setup`: the
    pair itself in most families).
    """

    #: family name (``TCAResult.family``)
    name: str = ""
    #: default grid of the family's TCA
    defaults: dict = dict(steps_per_pitch=24, half_pitches=1.25, n_pairs=3)
    #: True where :meth:`default_options` picks the grid for the design (the command
    #: line then leaves the grid to the family unless ``--pitches`` is given)
    grid_from_design: bool = False
    #: contact modes the family supports: (False,) point contact only; why, for the
    #: one-line refusal of the other mode
    line_contact_modes: tuple = (False,)
    contact_mode_reason: str = ""

    @property
    def program_key(self) -> str:
        """The family's key in the program store (gearjax/program_store.py): its class
        (a family object is stateless: the class is all that shapes its programs)."""
        return f"{type(self).__module__}.{type(self).__qualname__}"

    # -- concrete set-up ------------------------------------------------------------
    def pair(self, design):
        """The differentiable pytree of ``design`` (a design-file object or the pytree)."""
        return design

    def setup(self, design, side):
        """``(setup, side)``: the concrete set-up of ``design`` for ``side`` ("drive",
        "coast" or None: the family's choice, "drive" by default) -- the pair itself
        by default; a family that prepares a pair (a reference search, the flanks of
        the side) returns what it found, and the side its flanks decide.  Taking its
        own result back unchanged (``setup(setup, side)``)."""
        return self.pair(design), side or "drive"

    def early_setup(self, design, side):
        """Optional: a stand-in of :meth:`setup`'s set-up with the same structure and
        leaf types but placeholder values, computed without the set-up's work, or None
        (the default).  A family whose set-up is costly (a blank, a reference search)
        returns one, and the driver starts compiling the TCA's programs from it before
        the set-up runs (:mod:`gearjax.compile_ahead`)."""
        return None

    def user_pair(self, setup):
        """The differentiable pair of a set-up: what ``tca_function``'s ``f`` takes and
        the loaded chain differentiates (default: the set-up itself)."""
        return setup

    def program_pair(self, pair, setup):
        """The pytree the program runs on, from a user's differentiable ``pair`` and the
        concrete ``setup`` (default: ``pair``)."""
        return pair

    def default_options(self, pair) -> dict:
        """The default options of the concrete ``pair`` (:attr:`defaults`; a family
        whose grid or contact mode depends on the design overrides this)."""
        return dict(self.defaults)

    def split(self, pair):
        """``(blank, extra)``: the pair with its static fields that only enter arithmetic
        (e.g. tooth numbers) taken out as a traced array ``extra``, so that one compiled
        program serves every pair of the same options; :meth:`join` puts them back
        inside the trace.  Default: nothing static, ``(pair, None)``."""
        return pair, None

    def join(self, blank, extra):
        """The pair of :meth:`split` (inside a trace)."""
        return blank

    def check(self, design) -> None:
        """One-line ValueError for a concrete field out of range (traced: skipped)."""

    #: False: the reference contact is found once, concretely, by :meth:`reference`
    #: (the grid stays where it is when the design changes); True: inside the program
    #: by :meth:`reference_traced`, so that the grid moves with the design (its
    #: derivative flows)
    reference_moves_with_design: bool = False

    def reference(self, setup, side: str):
        """``(x_ref, phi1_ref)``: start of the contact solve at the middle grid point
        (concrete, from the set-up; no derivative flows into it)."""
        raise NotImplementedError

    def reference_traced(self, pair, drive, line_contact=False):
        """``(x_ref, phi1_ref, ok)`` inside the program (``reference_moves_with_design``);
        ``ok`` (bool) False where the reference itself could not be found (every point
        of the path is then marked not converged), or None (always found)."""
        raise NotImplementedError

    # -- traceable geometry ---------------------------------------------------------
    def flanks(self, pair, drive, line_contact=False):
        """``(r1, r2)``: pinion and gear flank functions ``uv -> (3,)`` (body frames, mm)
        of the side ``drive`` (traced bool); with ``line_contact`` parametrised so that
        the solved contact line's section is ``uv[1] = 0`` (:mod:`gearjax.tca.path`)."""
        raise NotImplementedError

    def refine_reference(self, pair, mis, r1, r2, x_ref, phi1_ref, line_contact):
        """``(x_ref, phi1_ref)`` refined inside the program before the grid is laid
        (traceable; e.g. the contact of the pinion's mean point under the
        misalignment ``mis``); default: unchanged."""
        return x_ref, phi1_ref

    def forward(self, pair, drive):
        """True where the side's pinion flank pushes the gear for increasing phi1."""
        return drive

    def assembly(self, pair):
        """The nominal mounting (:class:`gearjax.tca.assembly.Assembly`)."""
        raise NotImplementedError

    def pinion_teeth(self, pair):
        return pair.z1

    def boundaries(self, pair, path):
        """``(margin, coords)``: boundary margin of the contact (mm, >= 0 inside both
        flanks) and the family's flank coordinates of the contact (dict of arrays)."""
        raise NotImplementedError

    def path_position(self, pair, path, coords):
        """(N,) the position of the contact along its path in the family's own
        coordinate (``coords["path_position"]``, the objective of the same name of
        :meth:`~gearjax.tca.result.TCAResult.objectives`): by default the radius on the
        pinion (mm)."""
        return path.radial1

    def line_coords(self, pair, path, r1) -> dict:
        """Coordinates a line contact adds to :meth:`boundaries`' (e.g. the overlap
        ratio), from the path and the pinion flank ``r1``; default none."""
        return {}

    def edges(self, pair):
        """``(margin_parts, g1, g2, tips)`` of :func:`~gearjax.tca.edge_contact.face_end_contact`,
        or None (no edge contact solved)."""
        return None

    # -- writing a design back ------------------------------------------------------
    #: pair field -> (table, key, factor) of the design file: file value = field / factor
    #: (e.g. a field in rad written as a ``*_deg`` key: factor pi/180)
    file_fields: dict = {}

    def design_data(self, design, pair, side: str) -> dict:
        """The design file of ``design`` (dict, file units) with the concrete values of the
        differentiable ``pair`` (:meth:`user_pair` of the set-up of ``side``) written back:
        every field of :attr:`file_fields` whose value differs from the design's own.  A
        field that changed and has no key is a ValueError naming it.  The caller reads
        the dict back with :func:`gearjax.io.design_from_dict` (which validates it)."""
        from gearjax.fields import get_fields
        data = design.to_dict()
        new = get_fields(pair)
        old = get_fields(self.user_pair(self.setup(design, side)[0]))
        for name, value in new.items():
            a, a0 = np.asarray(value), np.asarray(old[name])
            if a.ndim or a0.ndim:            # an array field (e.g. per-member blade settings)
                if np.array_equal(a, a0):
                    continue
                raise ValueError(f"field {name!r} of a {self.name} pair (an array) has no "
                                 f"design-file key (writable: "
                                 f"{', '.join(self.file_fields) or 'none'})")
            v, v0 = float(a), float(a0)
            if v == v0:
                continue
            if name not in self.file_fields:
                raise ValueError(f"field {name!r} of a {self.name} pair has no design-file key "
                                 f"(writable: {', '.join(self.file_fields) or 'none'})")
            table, key, factor = self.file_fields[name]
            data.setdefault(table, {})[key] = v / factor
        return data

    # -- summaries, loaded contact, plots -------------------------------------------
    summary_keys: tuple = ()

    def summary(self, pair, res: TCAResult):
        raise NotImplementedError

    def teeth(self, setup, side: str, line_contact: bool = False):
        """``(teeth_of, pair)`` of the loaded-contact models for the set-up of ``side``:
        ``teeth_of(pair, res)`` and the differentiable pair it takes (ValueError where
        the family's loaded contact does not cover the pair)."""
        raise NotImplementedError

    def outline(self, pair, side: str = "drive") -> dict:
        """The pinion flank's outline for the TCA figure (concrete; ``pair`` of
        :meth:`pair`)."""
        raise NotImplementedError


def tca_parts(fam: GearFamily, pair, mis, x_ref, phi1_ref, drive, approach, *,
              steps_per_pitch: int, half_pitches: float, n_pairs: int, kinematics: bool,
              face_ends: bool = True, line_contact: bool = False):
    """The TCA of any family (traceable): ``(path, margin, multi, coords, kinematics)``.

    Grid ``phi1_ref + k 2 pi/(z1 steps_per_pitch)``, ``|k| <= round(half_pitches
    steps_per_pitch)``; the contact path continued from ``x_ref``; with ``face_ends``
    and the family's edges, the contact made at each angle is the surface or an edge
    contact; pair 0 shifted by whole pitches gives the neighbouring pairs and the TE
    envelope (max where :meth:`GearFamily.forward`, else min).  ``x_ref = None``: the
    family's :meth:`GearFamily.reference_traced` inside the program; the reference is
    then refined by :meth:`GearFamily.refine_reference` before the grid is laid.
    The two stages :func:`tca_surface` and :func:`tca_finish`."""
    surface = tca_surface(fam, pair, mis, x_ref, phi1_ref, drive, approach,
                          steps_per_pitch=steps_per_pitch, half_pitches=half_pitches,
                          line_contact=line_contact)
    return tca_finish(fam, pair, mis, drive, surface, steps_per_pitch=steps_per_pitch,
                      n_pairs=n_pairs, kinematics=kinematics, face_ends=face_ends,
                      line_contact=line_contact)


def tca_surface(fam: GearFamily, pair, mis, x_ref, phi1_ref, drive, approach, *,
                steps_per_pitch: int, half_pitches: float, line_contact: bool = False):
    """First stage of :func:`tca_parts`: the reference contact, the grid and the
    surface contact continued over it, its flank margins; ``(path, margin, coords)``."""
    ok = None
    if x_ref is None:
        x_ref, phi1_ref, ok = fam.reference_traced(pair, drive, line_contact)
    r1, r2 = fam.flanks(pair, drive, line_contact)
    x_ref, phi1_ref = fam.refine_reference(pair, mis, r1, r2, x_ref, phi1_ref, line_contact)
    grid = pinion_angle_grid(phi1_ref, fam.pinion_teeth(pair), steps_per_pitch, half_pitches)
    path = contact_path(r1, r2, fam.assembly(pair), mis, grid, x_ref,
                        line_contact=line_contact, approach=approach)
    if ok is not None:
        path = path._replace(converged=path.converged & ok)
    margin, coords = fam.boundaries(pair, path)
    return path, margin, coords


def tca_finish(fam: GearFamily, pair, mis, drive, surface, *, steps_per_pitch: int,
               n_pairs: int, kinematics: bool, face_ends: bool = True,
               line_contact: bool = False):
    """Second stage of :func:`tca_parts` from the first's ``surface = (path, margin,
    coords)``: the edge contacts, the tooth pairs and the kinematics; ``(path, margin,
    multi, coords, kinematics)``."""
    path, margin, coords = surface
    r1, r2 = fam.flanks(pair, drive, line_contact)
    asm = fam.assembly(pair)
    fwd = fam.forward(pair, drive)
    edges = fam.edges(pair) if face_ends else None
    if edges is not None:
        parts, g1, g2, tips = edges
        path, margin, _ = face_end_contact(r1, r2, asm, mis, path, margin, parts, g1, g2,
                                           drive=fwd, tips=tips, line_contact=line_contact,
                                           steps_per_pitch=steps_per_pitch)
        _, coords = fam.boundaries(pair, path)        # the coordinates of the contact made
    if line_contact:
        coords = {**coords, **fam.line_coords(pair, path, r1)}
    coords = {**coords, "path_position": fam.path_position(pair, path, coords)}
    multi = multi_pair(path, margin, steps_per_pitch, fam.pinion_teeth(pair), drive=fwd,
                       n_pairs=n_pairs)
    kin = (contact_kinematics(r1, r2, asm, mis, path, line_contact=line_contact)
           if kinematics else None)
    return path, margin, multi, coords, kin


_STATIC = ("fam", "steps_per_pitch", "half_pitches", "n_pairs", "kinematics", "face_ends",
           "line_contact")
_SURFACE_STATIC = ("fam", "steps_per_pitch", "half_pitches", "line_contact")
_FINISH_STATIC = ("fam", "steps_per_pitch", "n_pairs", "kinematics", "face_ends",
                  "line_contact")


# A concrete TCA runs as two programs, so that the second compiles while the first
# is traced and both compile at once (gearjax/compile_ahead.py).
@functools.partial(jax.jit, static_argnames=_SURFACE_STATIC)
def _surface_program(blank, extra, mis, x_ref, phi1_ref, approach, drive, *, fam, **static):
    return tca_surface(fam, fam.join(blank, extra), mis, x_ref, phi1_ref, drive, approach,
                       **static)


@functools.partial(jax.jit, static_argnames=_FINISH_STATIC)
def _finish_program(blank, extra, mis, drive, surface, *, fam, **static):
    return tca_finish(fam, fam.join(blank, extra), mis, drive, surface, **static)


def _program_args(fam, pair, mis, x_ref, phi1_ref, approach, side, static):
    """The arguments of the two programs: ``(a1, s1, a2, s2)``, the first program
    ``_surface_program(*a1, fam=fam, **s1)``, the second ``_finish_program(*a2,
    surface, fam=fam, **s2)``."""
    blank, extra = fam.split(strong_float64(pair))
    mis, drive = strong_float64(mis), jnp.asarray(side == "drive")
    s1 = {k: static[k] for k in _SURFACE_STATIC[1:]}
    s2 = {k: static[k] for k in _FINISH_STATIC[1:]}
    return (blank, extra, mis, x_ref, phi1_ref, approach, drive), s1, (blank, extra, mis, drive), s2


def _result(fam, pair, mis, x_ref, phi1_ref, approach, side, static, also=None) -> TCAResult:
    """The TCA by the two programs (inline inside a trace).  Concrete inputs: both
    compiled ahead side by side (with whatever ``also(ahead, abstract_result)`` submits
    to the same :class:`~gearjax.compile_ahead.CompileAhead`, e.g. the efficiency
    program)."""
    a1, s1, (blank, extra, mis, drive), s2 = _program_args(fam, pair, mis, x_ref, phi1_ref,
                                                           approach, side, static)
    with CompileAhead() as ahead:
        surface = ahead.submit(_surface_program, *a1, fam=fam, **s1)
        if surface is not None:
            parts = ahead.submit(_finish_program, blank, extra, mis, drive, surface, fam=fam,
                                 **s2)
            if also is not None:
                also(ahead, TCAResult(*parts, side, fam.name))
    if surface is None:
        # inside a trace (grad, vmap, the caller's jit): the two stages inline, not as
        # nested programs -- a transformation would trace each program and then
        # transform its jaxpr a second time, and partial evaluation across their
        # boundaries keeps residuals it can drop inline (the hypoid efficiency gradient:
        # 59 397 -> 55 148 instructions, a tenth less tracing; same values)
        pair = fam.join(blank, extra)
        surface = tca_surface(fam, pair, mis, x_ref, phi1_ref, drive, approach, **s1)
        parts = tca_finish(fam, pair, mis, drive, surface, **s2)
        return TCAResult(*parts, side, fam.name)
    surface = call(_surface_program, *a1, fam=fam, **s1)
    parts = call(_finish_program, blank, extra, mis, drive, surface, fam=fam, **s2)
    return TCAResult(*parts, side, fam.name)


def sensitivity_table(keys, vals, jac):
    """``(values, table)`` of concrete summary values ``vals`` and their derivatives by
    the misalignment (``jac``, a :class:`~gearjax.tca.assembly.Misalignment` of arrays):
    ``values[key]``, ``table[key] = {"dE": .., "dP": .., "dG": .., "dSigma": ..}``."""
    values = {k: float(v) for k, v in zip(keys, np.asarray(vals))}
    table = {k: {n: float(np.asarray(getattr(jac, n))[i]) for n in ("dE", "dP", "dG", "dSigma")}
             for i, k in enumerate(keys)}
    return values, table


class DriverAdapter:
    """The registry entry (:func:`gearjax.tca.result.register_family`) of a family
    ported to the driver: ``run``, ``traced``, ``sensitivity``, ``mesh``, ``outline``
    and ``check`` written once for every family."""

    def __init__(self, fam: GearFamily):
        self.fam = fam
        self.family = fam.name
        self.defaults = dict(fam.defaults)
        self.grid_from_design = fam.grid_from_design
        # the loaded chain's program takes the pair split the same way (one program for
        # every pair of the family)
        self.split_pair = fam.split
        self.join_pair = fam.join

    def check(self, design) -> None:
        self.fam.check(self.fam.pair(design))

    def design_data(self, design, pair, side: str = "drive") -> dict:
        """:meth:`GearFamily.design_data`: ``design``'s file with ``pair`` written back."""
        return self.fam.design_data(design, pair, check_side(side))

    def _reference(self, pair, side):
        # (None, None): found inside the program (the grid moves with the design)
        if self.fam.reference_moves_with_design:
            return None, None
        return self.fam.reference(pair, side)

    def options(self, options: dict, pair, *, run: bool = False):
        """``(approach, static options)`` with the family's defaults for the concrete
        ``pair`` (:meth:`GearFamily.default_options`), validated: an unknown option or
        an unsupported contact mode is a one-line ValueError."""
        allowed = set(OPTION_NAMES) | ({"throw"} if run else set())
        unknown = sorted(set(options) - allowed)
        if unknown:
            raise ValueError(f"unknown TCA option {unknown[0]!r} for {self.fam.name} pairs "
                             f"(options: {', '.join(OPTION_NAMES)})")
        o = {"line_contact": self.fam.line_contact_modes[0],
             **self.fam.default_options(pair), "approach": DEFAULT_APPROACH,
             "kinematics": True, "face_ends": True,
             **{k: v for k, v in options.items() if k != "throw" and v is not None}}
        lc = bool(o["line_contact"])
        if lc not in self.fam.line_contact_modes:
            why = f": {self.fam.contact_mode_reason}" if self.fam.contact_mode_reason else ""
            raise ValueError(f"line_contact = {lc} is not available for {self.fam.name} pairs"
                             f"{why} (allowed: None or "
                             f"{', '.join(str(m) for m in self.fam.line_contact_modes)})")
        check_tca_options(o["steps_per_pitch"], o["half_pitches"], o["n_pairs"], o["approach"])
        static = dict(steps_per_pitch=int(o["steps_per_pitch"]),
                      half_pitches=float(o["half_pitches"]), n_pairs=int(o["n_pairs"]),
                      kinematics=bool(o["kinematics"]), face_ends=bool(o["face_ends"]),
                      line_contact=lc)
        return float(o["approach"]), static

    def resolve(self, design, options: dict) -> dict:
        """The static options (grid, contact mode, ...) a TCA of ``design`` with
        ``options`` runs with, the family's defaults filled in."""
        return self.options(options, self.fam.pair(design))[1]

    def _setup(self, design, side):
        """``(setup, side)`` of :meth:`GearFamily.setup` (``side`` checked first)."""
        return self.fam.setup(design, None if side is None else check_side(side))

    def run(self, design, mis=None, *, side=None, also=None, **options) -> TCAResult:
        """Validated, jitted TCA; ``throw`` (default True) raises
        :class:`~gearjax.errors.ConvergenceError` (``NoContactError``) when a solve
        failed on the working flank or no grid point is on both flanks.  ``also(ahead,
        abstract_result)``: submits the programs that will run on the result to the
        :class:`~gearjax.compile_ahead.CompileAhead` that compiles the TCA's."""
        throw = options.get("throw", True)
        self._compile_early(design, mis, side, options)
        setup, side = self._setup(design, side)
        approach, static = self.options(options, setup, run=True)
        mis = Misalignment.zero() if mis is None else mis
        x_ref, phi1_ref = self._reference(setup, side)
        pair = self.fam.program_pair(self.fam.user_pair(setup), setup)
        res = _result(self.fam, pair, mis, x_ref, phi1_ref, approach, side, static, also)
        if throw:
            check_on_flank_converged(res.path, res.margin)
        return res

    def _compile_early(self, design, mis, side, options) -> None:
        """Start compiling the TCA's two programs from the family's
        :meth:`GearFamily.early_setup` (if it gives one) and go on: they compile while
        the set-up runs; the run's own submission then waits for them
        (:func:`gearjax.compile_ahead.prefetch`; the same abstract arguments, or else
        nothing is shared and the run compiles as without this).  Only after the side and
        the options have passed their checks, so that bad input is refused before any
        work; nothing here may change what the run raises or returns.  Once per family,
        design type, side and option set in a process (:func:`~gearjax.compile_ahead.
        first_time`): building the early arguments costs ~10 ms, and a later run finds
        its programs compiled."""
        if side is not None:
            check_side(side)
        try:
            if not first_time((self.fam, type(design), side or "drive",
                               tuple(sorted(options.items())))):
                return                  # once per option set: the later runs find it
            early = self.fam.early_setup(design, side)
            if early is None:
                return
            approach, static = self.options(options, early, run=True)
            side = side or "drive"
            x_ref, phi1_ref = self._reference(early, side)
            pair = self.fam.program_pair(self.fam.user_pair(early), early)
            mis = Misalignment.zero() if mis is None else mis
            a1, s1, a2, s2 = _program_args(self.fam, pair, mis, x_ref, phi1_ref, approach,
                                           side, static)
            surface = prefetch(_surface_program, *a1, fam=self.fam, **s1)
            if surface is not None:
                prefetch(_finish_program, *a2, surface, fam=self.fam, **s2)
        except Exception:   # bad input: the run itself refuses it, in its own words
            return

    def traced(self, design, *, side=None, **options):
        """A pure ``f(pair, mis=None, *, reference=None) -> TCAResult`` (the concrete
        set-up and reference contact of ``design`` fixed once here; ``reference =
        (x_ref, phi1_ref)`` replaces that reference guess, e.g. a traced one);
        ``f.pair`` the design's differentiable pair."""
        setup, side = self._setup(design, side)
        approach, static = self.options(options, setup)
        x_ref, phi1_ref = self._reference(setup, side)
        fam = self.fam

        def f(pair, mis=None, *, reference=None):
            mis = Misalignment.zero() if mis is None else mis
            xr, pr = (x_ref, phi1_ref) if reference is None else reference
            return _result(fam, fam.program_pair(pair, setup), mis, xr, pr, approach, side,
                           static)
        f.pair = fam.user_pair(setup)
        return f

    def sensitivity(self, design, mis=None, *, side=None, **options):
        """``(values, table)``: the family's summary and its derivatives by dE, dP, dG
        (per mm) and dSigma (per rad), by ``jax.jacfwd`` through every solve."""
        setup, side = self._setup(design, side)
        approach, static = self.options({**options, "kinematics": False}, setup)
        mis = Misalignment.zero() if mis is None else mis
        x_ref, phi1_ref = self._reference(setup, side)
        pair = self.fam.program_pair(self.fam.user_pair(setup), setup)
        vals, jac = _sensitivity_program(*self.fam.split(strong_float64(pair)),
                                         strong_float64(mis), x_ref, phi1_ref, approach,
                                         jnp.asarray(side == "drive"), fam=self.fam, **static)
        return sensitivity_table(self.fam.summary_keys, vals, jac)

    def mesh(self, design, *, side=None, **options):
        """``(teeth_of, pair, setup)`` of the loaded-contact models: the teeth, the
        differentiable pair and the set-up to run the TCA of (``options`` those of the
        TCA: the contact mode decides the teeth)."""
        setup, side = self._setup(design, side)
        lc = self.options({k: v for k, v in options.items() if k != "throw"},
                          setup)[1]["line_contact"]
        teeth_of, p = self.fam.teeth(setup, side, line_contact=lc)
        return teeth_of, p, setup

    def outline(self, design, side="drive"):
        return self.fam.outline(self.fam.pair(design), side)


@functools.partial(jax.jit, static_argnames=_STATIC)
def _sensitivity_program(blank, extra, mis, x_ref, phi1_ref, approach, drive, *, fam,
                         **static):
    pair = fam.join(blank, extra)

    def f(m):
        parts = tca_parts(fam, pair, m, x_ref, phi1_ref, drive, approach, **static)
        return fam.summary(pair, TCAResult(*parts, "", fam.name))
    # the values as the primal of the same forward-mode pass: the TCA runs once, not
    # twice (f(mis) beside jacfwd(f) was a second TCA in the program; the 10/30 spiral
    # bevel's table 446 -> 251 ms, docs/tca.md)
    jac, vals = jax.jacfwd(with_value(f), has_aux=True)(mis)
    return vals, jac
