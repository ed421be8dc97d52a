"""``gearjax example``: list the packaged example designs or print one."""

from __future__ import annotations

import sys


def register(sub):
    p = sub.add_parser("example", help="list or show packaged example designs",
                       description="Packaged example design files (TOML, mm and degrees).")
    s = p.add_subparsers(dest="example_cmd", metavar="ACTION")
    s.required = True
    s.add_parser("list", help="list example names").set_defaults(func=run_list)
    show = s.add_parser("show", help="print an example design file and the defaults it relies on")
    show.add_argument("name", help="example name (see 'gearjax example list')")
    show.set_defaults(func=run_show)


def run_list(args) -> int:
    """One line per packaged example: its name and the ``[design] description``.

    Listing reads the files' ``[design]`` tables only (TOML parse and ``kind``), it
    does not build the designs: no geometry, no compiled program (the full validation
    of every packaged example runs in ``gearjax example show`` and every command that
    loads it, and in tests/test_io.py).  A file that does not parse or names an
    unknown kind is reported on its line, not hidden."""
    import gearjax  # noqa: F401  (registers the families' design kinds)
    from gearjax.io import design_kinds, list_examples, read_toml
    kinds = design_kinds()
    for name in list_examples():
        try:
            des = read_toml(f"example:{name}").get("design", {})
            kind = des.get("kind") if isinstance(des, dict) else None
            if kind not in kinds:
                raise ValueError(f"[design] kind = {kind!r} must be one of "
                                 + ", ".join(repr(k) for k in kinds))
            desc = des.get("description", "")
        except ValueError as exc:
            desc = f"(invalid: {exc})"
        sys.stdout.write(f"{name:20s} {desc}\n")
    return 0


def run_show(args) -> int:
    """Print the file, then the documented defaults it relies on (keys left out of
    the file) as TOML comments, so that the printed text still loads."""
    from gearjax import example_path, load_design
    from gearjax.io import EXAMPLE_ALIASES
    name = EXAMPLE_ALIASES.get(args.name, args.name)
    text = example_path(name).read_text(encoding="utf-8")
    lines = load_design(f"example:{name}").defaults_lines()
    sys.stdout.write(text if text.endswith("\n") else text + "\n")
    sys.stdout.write("\n# defaults applied (keys not in this file; gearjax uses these values):"
                     + ("" if lines else " none") + "\n")
    for ln in lines:
        sys.stdout.write(f"#   {ln}\n")
    return 0
