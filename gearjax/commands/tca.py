"""``gearjax tca``: unloaded tooth contact analysis (see :mod:`gearjax.tca`).

DESIGN is an involute pair given inline,
``involute:z1=25,z2=41,m=2,alpha=20,b=20[,helix=0,x1=0,x2=0,dalpha=0,crown=0,lead_crown=0]``
(tooth numbers, normal module mm, normal pressure angle deg, face width mm, helix
deg, profile shifts, pinion pressure-angle change deg, pinion profile and lead
crown 1/mm).  Hypoid/spiral-bevel designs (``example:NAME`` or a file) are not yet
supported by TCA and are refused with one line.
"""

from __future__ import annotations

import argparse
import json
import math
import sys

import numpy as np

JSON_KEYS_DOC = """JSON keys:
  input            the design and options as given
  phi1_rad         pinion angles of the grid (rad); the reference (pitch point) in the middle
  te_arcsec        TE of tooth pair 0 (arcsec, > 0: gear ahead), null off the flank
  te_pairs_arcsec  TE of pairs -1, 0, +1 on the same grid (null where not on the flank)
  envelope_arcsec  unloaded TE envelope (max over pairs on the drive side, min on coast)
  ptp_arcsec       peak-to-peak of the sampled envelope over one pitch
  transfer_phi1_rad  pinion angles of the transfers into and out of pair 0
  contact_ratio    on-flank interval of pair 0 / angular pitch
  path             {axial1_mm, radial1_mm, axial2_mm, radial2_mm}: contact point on
                   pinion and gear flank in axial projection (body z, radius)
  ellipses         {semi_major_mm, semi_minor_mm}: contact ellipse (elastic approach
                   0.00632 mm; null = infinite, line contact)
  flags            {converged, on_flank, edge}: per grid point (edge: converged but
                   outside a flank boundary)"""


def register(sub):
    p = sub.add_parser(
        "tca", help="tooth contact analysis: TE, path of contact, contact ellipses",
        description="Unloaded tooth contact analysis of an involute pair (optionally with a "
                    "crowned or mismatched pinion and misalignments).",
        epilog=JSON_KEYS_DOC, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("design", help="involute:z1=..,z2=..,m=..,alpha=..,b=..[,...] (see above)")
    p.add_argument("--side", choices=["drive", "coast"], default="drive")
    p.add_argument("--misalign", default="",
                   help="dE=mm,dP=mm,dG=mm,dSigma=deg (any subset; default all 0)")
    p.add_argument("--positions", type=float, default=61,
                   help="grid positions, 10k+1 (k >= 1): 4k steps per pitch, "
                        "1.25 pitches each side")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument("--plot", default=None, help="write the TE and contact-pattern figure (PNG)")
    p.set_defaults(func=run)


_ALLOWED = {"z1", "z2", "m", "alpha", "b", "helix", "x1", "x2", "dalpha", "crown", "lead_crown"}


def _parse_kv(text, allowed, what):
    out = {}
    for item in filter(None, (s.strip() for s in text.split(","))):
        if "=" not in item:
            raise ValueError(f"{what}: {item!r} is not KEY=VALUE")
        k, v = (s.strip() for s in item.split("=", 1))
        if k not in allowed:
            raise ValueError(f"{what}: unknown key {k!r} (allowed: {', '.join(sorted(allowed))})")
        try:
            out[k] = float(v)
        except ValueError:
            raise ValueError(f"{what}: {k} = {v!r} must be a number") from None
    return out


def _design(text):
    from ..gears.involute import InvolutePair
    from ..tca_involute import InvoluteTCA

    if not text.startswith("involute:"):
        raise ValueError(f"design {text!r}: tooth contact analysis supports involute pairs "
                         "('involute:z1=..,z2=..,m=..,alpha=..,b=..'); hypoid/spiral-bevel TCA "
                         "is not implemented yet")
    kv = _parse_kv(text[len("involute:"):], _ALLOWED, "design")
    missing = [k for k in ("z1", "z2", "m", "alpha", "b") if k not in kv]
    if missing:
        raise ValueError(f"design: missing {', '.join(missing)}")
    pair = InvolutePair.create(kv["z1"], kv["z2"], kv["m"], kv["alpha"], kv.get("helix", 0.0),
                               kv.get("x1", 0.0), kv.get("x2", 0.0))
    return kv, InvoluteTCA.create(pair, kv["b"], kv.get("dalpha", 0.0), kv.get("crown", 0.0),
                                  kv.get("lead_crown", 0.0))


def _nan_list(a):
    a = np.asarray(a, float)
    return [None if not np.isfinite(x) else float(x) for x in a.ravel()]


def run(args) -> int:
    from ..errors import ConvergenceError, check_int
    from ..tca import ARCSEC, Misalignment, NoContactError
    from ..tca_involute import involute_tca

    kv, des = _design(args.design)
    mis_kv = _parse_kv(args.misalign, {"dE", "dP", "dG", "dSigma"}, "misalign")
    mis = Misalignment.create(mis_kv.get("dE", 0.0), mis_kv.get("dP", 0.0),
                              mis_kv.get("dG", 0.0), mis_kv.get("dSigma", 0.0))
    n = check_int("positions", args.positions, lo=11, hi=1001)
    if (n - 1) % 10:
        raise ValueError(f"positions = {n} must be of the form 10k+1 (11, 21, ..., 61, ...)")
    m = 4 * ((n - 1) // 10)
    side = -1 if args.side == "drive" else 1
    try:
        path, margin, multi = involute_tca(des, mis, side=side, steps_per_pitch=m,
                                           half_pitches=1.25)
    except NoContactError:
        sys.stderr.write("gearjax: error: the flanks do not touch inside their boundaries "
                         "(no on-flank contact at any grid position)\n")
        return 3
    except ConvergenceError as exc:
        sys.stderr.write(f"gearjax: error: the contact solve failed: {exc}\n")
        return 3
    conv = np.asarray(path.converged)
    on = (np.asarray(margin) >= 0.0) & conv
    te = np.where(on, np.asarray(path.te), np.nan) / ARCSEC
    if args.plot:
        from ..plot_tca import save_tca_plot
        from ..tca_involute import involute_limits
        save_tca_plot(args.plot, [(args.side, path, margin, multi)], involute_limits(des, side),
                      title="involute TCA")
    sm = np.asarray(path.semi_major)
    out = {
        "input": {"design": args.design, "side": args.side, "misalign": mis_kv, "positions": n},
        "phi1_rad": _nan_list(path.phi1),
        "te_arcsec": _nan_list(te),
        "te_pairs_arcsec": [_nan_list(r) for r in np.asarray(multi.te_pairs) / ARCSEC],
        "envelope_arcsec": _nan_list(np.asarray(multi.envelope) / ARCSEC),
        "ptp_arcsec": float(multi.ptp) / ARCSEC,
        "transfer_phi1_rad": _nan_list(multi.transfer_phi1),
        "contact_ratio": float(multi.contact_ratio),
        "path": {k: _nan_list(getattr(path, k[:-3])) for k in
                 ("axial1_mm", "radial1_mm", "axial2_mm", "radial2_mm")},
        "ellipses": {"semi_major_mm": _nan_list(sm),
                     "semi_minor_mm": _nan_list(path.semi_minor)},
        "flags": {"converged": conv.tolist(), "on_flank": on.tolist(),
                  "edge": (conv & ~on).tolist()},
    }
    if args.json:
        print(json.dumps(out, indent=1))
        return 0
    print(f"# TCA {args.design} ({args.side}); misalign {mis_kv or 'none'}")
    print(f"# TE p-t-p {out['ptp_arcsec']:.4f} arcsec, contact ratio {out['contact_ratio']:.4f}")
    print(f"{'phi1[deg]':>10s} {'TE[arcsec]':>11s} {'axial1':>9s} {'radius1':>9s} "
          f"{'2a[mm]':>8s} {'2b[mm]':>8s} flag")
    for i in range(n):
        flag = "ok" if on[i] else ("edge" if conv[i] else "no-conv")
        print(f"{math.degrees(float(path.phi1[i])):10.4f} {te[i]:11.5f} "
              f"{float(path.axial1[i]):9.4f} {float(path.radial1[i]):9.4f} "
              f"{2 * sm[i]:8.4f} {2 * float(path.semi_minor[i]):8.4f} {flag}")
    return 0
