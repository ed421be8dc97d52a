"""``gearjax friction`` and ``gearjax stribeck``: mixed-lubrication friction of one
contact and Stribeck sweeps (see :mod:`gearjax.tribology` and docs/friction.md).

Speeds on the command line are in **m/s** (converted to the library's mm/s here),
roughness and asperity radius in µm, radii in mm, load in N, viscosity in Pa·s.
"""

from __future__ import annotations

import argparse
import math
import warnings

import numpy as np

from gearjax.errors import check_range

#: figure formats accepted by --plot
PLOT_SUFFIXES = (".png", ".pdf", ".svg")

FRICTION_KEYS_DOC = """JSON keys (friction):
  a_mm, b_mm            Hertz semi-axes: a transverse (along Ry), b rolling (along Rx) (mm)
  k                     ellipticity a/b (-)
  p_max_MPa             maximum Hertz pressure (MPa)
  h_c_um, h_min_um      central / minimum film thickness under load sharing (um)
  h_c_smooth_um         central film of smooth surfaces (um)
  lambda                h_c / sigma under load sharing (-)
  lambda_smooth         h_c_smooth / sigma, classical specific film thickness (-)
  asperity_load_ratio   F_a / F_n (-)
  real_area_ratio       real / nominal contact area (Greenwood-Tripp) (-)
  mu, mu_boundary, mu_fluid  friction coefficient and its asperity / fluid parts (-)
  friction_force_N      mu F_n (N)
  sliding_power_W       mu F_n u_s (W)
  regime                "boundary" | "mixed" | "full film"
  input                 the inputs in CLI units (speeds m/s)"""

STRIBECK_KEYS_DOC = """JSON keys (stribeck): arrays over the speed sweep
  u_e_m_s, u_s_m_s      entrainment / sliding speed (m/s)
  stribeck_number_per_m eta0 u_e / F_n (1/m)
  lambda_smooth, lambda, asperity_load_ratio, mu, mu_boundary, mu_fluid, h_c_um, regime
plus p_max_MPa, a_mm, b_mm (constant along the sweep), input, and plot (the PNG path or null)."""


#: accepted ranges of the operating inputs, (low, high, low bound excluded, unit); the
#: library validates the same quantities (gearjax.contact, gearjax.tribology)
RANGES = {
    "--load-N": (1e-3, 1e7, False, "N"),
    "--rx-mm": (0.0, 1e6, True, "mm"),
    "--ry-mm": (0.0, 1e6, True, "mm"),
    "--eta0": (math.exp(-9.67), 100.0, True, "Pa·s"),
    "--alpha-per-GPa": (0.0, 100.0, True, "1/GPa"),
    "--tau0-MPa": (0.0, 100.0, True, "MPa"),
    "--sigma-um": (0.0, 10.0, True, "um"),
    "--asperity-density-per-mm2": (0.0, 1e6, True, "1/mm^2"),
    "--asperity-radius-um": (0.0, 1000.0, True, "um"),
    "--fc": (0.0, 1.0, False, ""),
    "--E-prime-MPa": (0.0, 1e7, True, "MPa"),
    "--ue": (1e-6, 500.0, False, "m/s"),
    "--us": (0.0, 500.0, False, "m/s"),
    "--ue-min": (1e-6, 500.0, False, "m/s"),
    "--ue-max": (1e-6, 500.0, False, "m/s"),
    "--srr": (0.0, 2.0, False, ""),
}


def check_flag(flag, value):
    """``value`` of option ``flag`` checked against :data:`RANGES` (one-line ValueError)."""
    lo, hi, lo_open, unit = RANGES[flag]
    return check_range(flag, value, lo, hi, lo_open=lo_open, unit=unit)


def _add_common(p):
    p.add_argument("--load-N", type=float, required=True, help="normal load F_n (N, in [1e-3, 1e7])")
    p.add_argument("--rx-mm", type=float, required=True,
                   help="relative radius of curvature in the rolling direction (mm, in (0, 1e6])")
    p.add_argument("--ry-mm", type=float, required=True,
                   help="relative radius of curvature in the transverse direction (mm, in (0, 1e6])")
    add_lubricant_options(p)
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")


#: help of --E-prime-MPa in the friction and stribeck commands
E_PRIME_HELP = ("reduced modulus E' = 2/((1-v1^2)/E1+(1-v2^2)/E2) (MPa, in (0, 1e7]; "
                "default steel 226374)")


def add_lubricant_options(p, e_prime_help: str | None = E_PRIME_HELP, required: bool = True):
    """The oil (--oil NAME, or --eta0 with --alpha-per-GPa/--tau0-MPa), surface
    (--sigma-um, asperity options, --fc), --E-prime-MPa, --film and --viscosity
    options shared by the friction, stribeck, efficiency and loaded commands
    (read back by :func:`lubricant_from_args`); ``e_prime_help`` the help of
    --E-prime-MPa (its default differs between commands; None: no such option, the
    design's material applies); ``required=False`` where the lubrication is optional
    (the command checks that the oil and --sigma-um come together)."""
    g = p.add_mutually_exclusive_group(required=required)
    g.add_argument("--oil", help="example oil: mineral_vg100 | mineral_vg220 | pao_vg100 "
                                 "(gearjax.tribology.OILS)")
    g.add_argument("--eta0", type=float, help="inlet viscosity (Pa·s, in (6.31e-5, 100])")
    p.add_argument("--alpha-per-GPa", type=float, default=None,
                   help="pressure-viscosity coefficient with --eta0 (1/GPa, in (0, 100], default 20)")
    p.add_argument("--tau0-MPa", type=float, default=None,
                   help="Eyring stress with --eta0 (MPa, in (0, 100], default 5)")
    p.add_argument("--sigma-um", type=float, required=required,
                   help="composite RMS roughness sqrt(s1^2+s2^2) (um, in (0, 10])")
    p.add_argument("--asperity-density-per-mm2", type=float, default=1e4,
                   help="asperity density (1/mm^2, in (0, 1e6], default 1e4)")
    p.add_argument("--asperity-radius-um", type=float, default=10.0,
                   help="asperity tip radius (um, in (0, 1000], default 10)")
    p.add_argument("--fc", type=float, default=0.1,
                   help="boundary friction coefficient (in [0, 1], default 0.1)")
    if e_prime_help is not None:
        p.add_argument("--E-prime-MPa", type=float, default=None, help=e_prime_help)
    p.add_argument("--film", choices=["auto", "point", "line"], default="auto",
                   help="film formula (default auto: Hamrock-Dowson blended into line contact)")
    p.add_argument("--viscosity", choices=["roelands", "barus"], default="roelands")


def register(sub):
    p = sub.add_parser("friction", help="mixed-lubrication friction of one contact",
                       description="Hertz contact, EHL film, asperity load sharing and friction "
                                   "coefficient of one lubricated contact (Reynolds film, Greenwood-Williamson asperities, Ree-Eyring shear).",
                       epilog=FRICTION_KEYS_DOC, formatter_class=argparse.RawDescriptionHelpFormatter)
    _add_common(p)
    p.add_argument("--ue", type=float, required=True,
                   help="entrainment speed (u1+u2)/2 (m/s, in [1e-6, 500])")
    p.add_argument("--us", type=float, required=True,
                   help="sliding speed |u1-u2| (m/s, in [0, 500])")
    p.set_defaults(func=run_friction)

    s = sub.add_parser("stribeck", help="Stribeck curve (mu against eta0 u_e / F_n)",
                       description="Friction coefficient over an entrainment-speed sweep at fixed "
                                   "slide-to-roll ratio.",
                       epilog=STRIBECK_KEYS_DOC, formatter_class=argparse.RawDescriptionHelpFormatter)
    _add_common(s)
    s.add_argument("--srr", type=float, default=0.2, help="slide-to-roll ratio u_s/u_e (in [0, 2])")
    s.add_argument("--ue-min", type=float, default=0.01,
                   help="lowest entrainment speed (m/s, in [1e-6, 500])")
    s.add_argument("--ue-max", type=float, default=30.0,
                   help="highest entrainment speed (m/s, in [1e-6, 500], > --ue-min)")
    s.add_argument("--points", type=float, default=40, help="number of speeds (integer 2..2000)")
    s.add_argument("--plot", default=None,
                   help="write the Stribeck curve to this file (.png, .pdf or .svg)")
    s.set_defaults(func=run_stribeck)


def _materials(args):
    for flag in ("--load-N", "--rx-mm", "--ry-mm"):
        check_flag(flag, getattr(args, flag[2:].replace("-", "_")))
    ratio = max(args.rx_mm, args.ry_mm) / min(args.rx_mm, args.ry_mm)
    if ratio > 1e15:
        raise ValueError(f"--ry-mm / --rx-mm = {args.ry_mm / args.rx_mm:g} is outside the "
                         "allowed range [1e-15, 1e15]")
    return lubricant_from_args(args)


def lubricant_from_args(args):
    """``(Oil, Surface, E')`` from the options of :func:`add_lubricant_options`,
    each checked against :data:`RANGES` (one-line ValueError naming the option; an
    unknown --oil lists the known ones).  Model-range warnings of ``make_oil`` are
    Python warnings (the commands print them as ``gearjax: warning:`` lines)."""
    from gearjax.tribology import get_oil, make_oil, make_surface
    from gearjax.tribology.friction import STEEL_E_PRIME

    for flag in ("--sigma-um", "--asperity-density-per-mm2", "--asperity-radius-um", "--fc"):
        check_flag(flag, getattr(args, flag[2:].replace("-", "_")))
    if args.oil is not None:
        for flag in ("--alpha-per-GPa", "--tau0-MPa"):
            if getattr(args, flag[2:].replace("-", "_")) is not None:
                raise ValueError(f"{flag} applies with --eta0 only: --oil {args.oil} brings its "
                                 "own pressure-viscosity coefficient and Eyring stress")
        oil = get_oil(args.oil)
    else:
        if args.alpha_per_GPa is None:
            args.alpha_per_GPa = 20.0
        if args.tau0_MPa is None:
            args.tau0_MPa = 5.0
        for flag in ("--eta0", "--alpha-per-GPa", "--tau0-MPa"):
            check_flag(flag, getattr(args, flag[2:].replace("-", "_")))
        oil = make_oil(args.eta0, args.alpha_per_GPa, args.tau0_MPa)
    surf = make_surface(args.sigma_um, args.asperity_density_per_mm2, args.asperity_radius_um, args.fc)
    e_prime = getattr(args, "E_prime_MPa", None)
    Ep = STEEL_E_PRIME if e_prime is None else check_flag("--E-prime-MPa", e_prime)
    return oil, surf, Ep


def _input_dict(args, oil, Ep):
    d = {k: v for k, v in vars(args).items() if k not in ("func", "command", "json")}
    d.update(eta0_Pas=float(oil.eta0), alpha_per_GPa=float(oil.alpha) * 1e3, roelands_z=float(oil.z),
             tau0_MPa=float(oil.tau0), E_prime_MPa=float(Ep))
    return d


def run_friction(args) -> int:
    from gearjax.tribology import REGIMES, friction_coefficient

    from gearjax.commands import print_json, warn_nonfinite

    check_flag("--ue", args.ue)
    check_flag("--us", args.us)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        oil, surf, Ep = _materials(args)
        r = friction_coefficient(args.load_N, args.ue * 1e3, args.us * 1e3, args.rx_mm, args.ry_mm,
                                 oil, surf, Ep, viscosity_model=args.viscosity, film_method=args.film)
    import sys
    for w in caught:
        sys.stderr.write(f"gearjax: warning: {w.message}\n")
    out = {
        "a_mm": float(r.a), "b_mm": float(r.b), "k": float(r.k), "p_max_MPa": float(r.p_max),
        "h_c_um": float(r.h_c) * 1e3, "h_min_um": float(r.h_min) * 1e3,
        "h_c_smooth_um": float(r.lam_smooth) * float(surf.sigma) * 1e3,
        "lambda": float(r.lam), "lambda_smooth": float(r.lam_smooth),
        "asperity_load_ratio": float(r.phi), "real_area_ratio": float(r.area_ratio),
        "mu": float(r.mu), "mu_boundary": float(r.mu_boundary), "mu_fluid": float(r.mu_fluid),
        "friction_force_N": float(r.friction_force),
        "sliding_power_W": float(r.friction_force) * args.us,
        "regime": REGIMES[int(r.regime)], "input": _input_dict(args, oil, Ep),
    }
    if args.json:
        print_json(out, indent=2)
        return 0
    warn_nonfinite(k for k, v in out.items() if isinstance(v, float) and not math.isfinite(v))
    rows = [("Hertz a x b", f"{out['a_mm']:.4f} x {out['b_mm']:.4f} mm (k = {out['k']:.3f})"),
            ("p_max", f"{out['p_max_MPa']:.1f} MPa"),
            ("film h_c / h_min", f"{out['h_c_um']:.4f} / {out['h_min_um']:.4f} um (smooth h_c "
                                 f"{out['h_c_smooth_um']:.4f} um)"),
            ("lambda (shared / smooth)", f"{out['lambda']:.3f} / {out['lambda_smooth']:.3f}"),
            ("asperity load ratio", f"{out['asperity_load_ratio']:.4g}"),
            ("regime", out["regime"]),
            ("mu (boundary + fluid)", f"{out['mu']:.5f} = {out['mu_boundary']:.5f} + {out['mu_fluid']:.5f}"),
            ("friction force", f"{out['friction_force_N']:.3f} N"),
            ("sliding power loss", f"{out['sliding_power_W']:.3f} W")]
    for k, v in rows:
        print(f"{k:26s} {v}")
    return 0


def run_stribeck(args) -> int:
    from gearjax.commands import print_json, warn_nonfinite
    from gearjax.errors import check_int
    from gearjax.io import check_output_path
    from gearjax.tribology import REGIMES, stribeck_curve

    for flag in ("--srr", "--ue-min", "--ue-max"):
        check_flag(flag, getattr(args, flag[2:].replace("-", "_")))
    if args.ue_max <= args.ue_min:
        raise ValueError(f"--ue-max = {args.ue_max:g} m/s must exceed --ue-min = {args.ue_min:g} m/s")
    n = check_int("--points", args.points, 2, 2000)
    if args.plot is not None:
        check_output_path(args.plot, "--plot", PLOT_SUFFIXES)
    ue = np.logspace(np.log10(args.ue_min), np.log10(args.ue_max), n) * 1e3
    from gearjax.progress import Progress
    with warnings.catch_warnings(record=True) as caught, \
            Progress(1, "stribeck") as bar, bar.phase(f"{n} speeds"):
        warnings.simplefilter("always")
        oil, surf, Ep = _materials(args)
        c = stribeck_curve(args.load_N, args.rx_mm, args.ry_mm, args.srr, ue, oil, surf, Ep,
                           viscosity_model=args.viscosity, film_method=args.film)
    import sys
    for w in caught:
        sys.stderr.write(f"gearjax: warning: {w.message}\n")
    fr = c.friction
    if args.plot is not None:
        from gearjax.io import atomic_write_figure
        from gearjax.plot.tribology import stribeck_figure
        fig = stribeck_figure([c], [f"F = {args.load_N:g} N, sigma = {args.sigma_um:g} um"])
        atomic_write_figure(fig, args.plot, dpi=120)
    out = {
        "u_e_m_s": (ue * 1e-3).tolist(), "u_s_m_s": (ue * 1e-3 * args.srr).tolist(),
        "stribeck_number_per_m": np.asarray(c.stribeck_number).tolist(),
        "lambda_smooth": np.asarray(c.lam).tolist(), "lambda": np.asarray(fr.lam).tolist(),
        "asperity_load_ratio": np.asarray(fr.phi).tolist(), "mu": np.asarray(c.mu).tolist(),
        "mu_boundary": np.asarray(fr.mu_boundary).tolist(), "mu_fluid": np.asarray(fr.mu_fluid).tolist(),
        "h_c_um": (np.asarray(fr.h_c) * 1e3).tolist(),
        "regime": [REGIMES[int(g)] for g in np.asarray(fr.regime)],
        "p_max_MPa": float(fr.p_max[0]), "a_mm": float(fr.a[0]), "b_mm": float(fr.b[0]),
        "input": _input_dict(args, oil, Ep), "plot": args.plot,
    }
    if args.json:
        print_json(out, indent=2)
        return 0
    warn_nonfinite(f"{k}[{i}]" for k in ("stribeck_number_per_m", "lambda_smooth", "lambda",
                                          "asperity_load_ratio", "mu", "h_c_um")
                   for i, v in enumerate(out[k]) if not math.isfinite(v))
    print(f"p_max = {out['p_max_MPa']:.1f} MPa, SRR = {args.srr:g}")
    print(f"{'u_e m/s':>10} {'eta0 ue/F 1/m':>14} {'lambda_s':>9} {'F_a/F_n':>9} {'mu':>8}  regime")
    for i in range(n):
        print(f"{out['u_e_m_s'][i]:10.4g} {out['stribeck_number_per_m'][i]:14.4g} "
              f"{out['lambda_smooth'][i]:9.3f} {out['asperity_load_ratio'][i]:9.3g} "
              f"{out['mu'][i]:8.5f}  {out['regime'][i]}")
    if args.plot:
        print(f"plot written to {args.plot}")
    return 0
