"""Run the command line in-process and capture what it wrote."""

import contextlib
import io

from gearjax.cli import main


def cli_call(argv):
    """``(status, stdout, stderr)`` of ``gearjax ARGV`` run in this process; argparse's
    refusals (``SystemExit``, one line, status 2) are returned as a status."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main(argv)
        except SystemExit as exc:
            rc = exc.code
    return rc, out.getvalue(), err.getvalue()
