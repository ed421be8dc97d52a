"""The design-file registry: ``[design] kind`` -> the family reader that owns it.

Families register their kinds when imported (:func:`register_design_kind`);
:func:`load_design` and :func:`design_from_dict` dispatch on the kind and name the
known ones for an unknown kind.  Nothing here knows a family.
"""

from __future__ import annotations

from gearjax.io.toml import check_string, read_toml, require_key, type_name


class DesignFileMixin:
    """``name`` and ``to_dict`` of a family's design-file object from its validated
    ``data`` dict (file units) -- the part every family's file class shares."""

    @property
    def name(self) -> str:
        return self.data.get("design", {}).get("name", "")

    def to_dict(self) -> dict:
        import copy
        return copy.deepcopy(self.data)


# design files of every family: one loader, dispatched on [design] kind

#: kind -> reader(data: dict) -> design; filled by the families when they are imported
_DESIGN_READERS: dict = {}


def register_design_kind(kind: str, reader) -> None:
    """Register the reader of the design files whose ``[design] kind`` is ``kind``.

    ``reader(data)`` validates a parsed design file (file units: mm, degrees) and
    returns the family's design object, or raises ``ValueError`` naming the table
    and the key.  The object provides ``name`` (str), ``data`` (the validated dict,
    written back by ``save_design``) and ``defaults_lines()`` (the documented
    defaults it relies on, printed by ``gearjax example show``).  So that the
    contact commands take it, its type is registered with
    ``gearjax.tca.result.register_family`` (``gearjax tca`` and ``gearjax efficiency``
    call ``run_tca(design, mis, side=...)`` / ``mesh_efficiency``); so that
    ``gearjax surface`` takes it, it provides ``surface_grid(member, flank, n_u, n_v)``
    (a grid with ``points``, ``normals`` (n_u, n_v, 3), ``params`` (n_u, n_v, k), ``xi``
    (n_u,), ``residual`` and ``converged`` (n_u, n_v): see :func:`write_csv`) and
    ``teeth(member)`` (int).  The hypoid family registers ``hypoid`` and
    ``spiral_bevel``.
    """
    _DESIGN_READERS[kind] = reader


def design_kinds() -> tuple:
    """The ``[design] kind`` values a design file may have (registered families)."""
    return tuple(sorted(_DESIGN_READERS))


def design_from_dict(data, kinds=None):
    """A design object from a parsed design file, by its ``[design] kind``.

    ``kinds`` restricts the accepted kinds (a command made for one family);
    ``ValueError`` naming the table and the key for a missing, unknown or refused kind."""
    if not isinstance(data, dict):
        raise ValueError(f"a design must be a table (dict), got {type_name(data)}")
    des = data.get("design")
    if not isinstance(des, dict):
        raise ValueError("missing table [design] (with kind = one of "
                         + ", ".join(repr(k) for k in design_kinds()) + ")")
    kind = check_string("design", "kind", require_key("design", des, "kind"), design_kinds())
    if kinds is not None and kind not in kinds:
        raise ValueError(f"[design] kind = {kind!r}: this command takes "
                         + " or ".join(repr(k) for k in kinds) + " designs")
    return _DESIGN_READERS[kind](data)


def load_design(source, kinds=None):
    """Load and validate a design file of any registered family: a path or
    ``example:NAME``.  ``ValueError`` (one line naming the file, the table and the
    key) for any invalid input; ``kinds`` as in :func:`design_from_dict`."""
    data = read_toml(source)
    try:
        return design_from_dict(data, kinds)
    except ValueError as exc:
        raise ValueError(f"design file {str(source)!r}: {exc}") from None
