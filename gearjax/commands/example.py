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
    from gearjax import list_examples, load_design
    for name in list_examples():
        try:
            desc = load_design(f"example:{name}").data.get("design", {}).get("description", "")
        except ValueError as exc:   # an example that no longer validates is reported, not hidden
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
