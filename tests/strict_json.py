"""Read a command's JSON output strictly: NaN or Infinity (not JSON) fail the test."""

import json


def strict_json(text):
    """``json.loads(text)``, raising ``AssertionError`` on the non-strict constants."""
    def no_constant(name):
        raise AssertionError(f"non-strict JSON constant {name}")
    return json.loads(text, parse_constant=no_constant)
