"""The DESIGN argument and ``--misalign`` of the contact commands (``gearjax tca``,
``gearjax efficiency``): one parser for both.

DESIGN is either an involute pair given inline,
``involute:z1=25,z2=41,m=2,alpha=20,b=20[,helix=0,x1=0,x2=0,dalpha=0,crown=0,lead_crown=0]``
(tooth numbers, normal module mm, normal pressure angle deg, face width mm, helix
deg, profile shifts, pinion pressure-angle change deg, pinion profile and lead
crown 1/mm), or a design file of any kind (a path or ``example:NAME``; kind
``involute`` is the file form of the inline pair).
Every function here validates and raises ``ValueError`` with one line naming the
key, its value and the allowed range.
"""

from __future__ import annotations

__all__ = ["MAX_FACE_WIDTH_MM", "INVOLUTE_KEYS", "MISALIGN_KEYS", "INVOLUTE_PREFIX", "parse_kv",
           "involute_design", "parse_misalign", "is_involute"]

#: widest accepted face width of an inline involute design (mm)
MAX_FACE_WIDTH_MM = 1000.0

#: keys of an inline involute design and of ``--misalign``
INVOLUTE_KEYS = frozenset({"z1", "z2", "m", "alpha", "b", "helix", "x1", "x2", "dalpha", "crown",
                           "lead_crown"})
MISALIGN_KEYS = frozenset({"dE", "dP", "dG", "dSigma"})
INVOLUTE_PREFIX = "involute:"


def is_involute(text: str) -> bool:
    """Whether DESIGN is an inline involute pair (else a design file or example)."""
    return text.startswith(INVOLUTE_PREFIX)


def parse_kv(text, allowed, what):
    """``"k=v,k=v"`` -> ``{k: float}``; unknown, repeated or non-numeric keys refused."""
    out = {}
    for item in filter(None, (s.strip() for s in text.split(","))):
        if "=" not in item:
            raise ValueError(f"{what}: {item!r} is not KEY=VALUE")
        k, v = (s.strip() for s in item.split("=", 1))
        if k not in allowed:
            raise ValueError(f"{what}: unknown key {k!r} (allowed: {', '.join(sorted(allowed))})")
        if k in out:
            raise ValueError(f"{what}: {k} is given twice")
        try:
            out[k] = float(v)
        except ValueError:
            raise ValueError(f"{what}: {k} = {v!r} must be a number") from None
    return out


def involute_design(text):
    """``(keys, InvoluteTCA)`` of an inline ``involute:...`` DESIGN (validated)."""
    from gearjax.involute import InvolutePair, InvoluteTCA
    from gearjax.errors import check_range

    kv = parse_kv(text[len(INVOLUTE_PREFIX):], INVOLUTE_KEYS, "design")
    missing = [k for k in ("z1", "z2", "m", "alpha", "b") if k not in kv]
    if missing:
        raise ValueError(f"design: missing {', '.join(missing)}")
    check_range("design b (face width)", kv["b"], 0.0, MAX_FACE_WIDTH_MM, lo_open=True, unit="mm")
    pair = InvolutePair.create(kv["z1"], kv["z2"], kv["m"], kv["alpha"], kv.get("helix", 0.0),
                               kv.get("x1", 0.0), kv.get("x2", 0.0))
    return kv, InvoluteTCA.create(pair, kv["b"], kv.get("dalpha", 0.0), kv.get("crown", 0.0),
                                  kv.get("lead_crown", 0.0))


def parse_misalign(text):
    """``(keys, Misalignment)`` of a ``--misalign dE=..,dP=..,dG=..,dSigma=..`` value
    (mm, mm, mm, deg; any subset, default 0; validated by ``Misalignment.create``)."""
    from gearjax import Misalignment

    kv = parse_kv(text, MISALIGN_KEYS, "misalign")
    return kv, Misalignment.create(kv.get("dE", 0.0), kv.get("dP", 0.0), kv.get("dG", 0.0),
                                   kv.get("dSigma", 0.0))
