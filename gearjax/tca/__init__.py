"""Tooth contact analysis, written once for every gear family.

``family`` (the interface a family implements and the one driver), ``assembly`` (the
mounting and the misalignments), ``path`` (the contact equations of two flanks and
their continuation along the mesh cycle), ``edge_contact`` and ``corners`` (contact at
the face ends, tip edges and their corners), ``multi_pair`` (the neighbouring tooth
pairs and the loaded envelope), ``result`` (the one result type, the kinematics at its
contact points, the family registry).  The public entry points are
:func:`gearjax.run_tca`, :func:`gearjax.tca_function` and :func:`gearjax.tca_sensitivity`;
the names below are what a new family and the command line need from here.
"""

from gearjax.tca.edge_contact import EDGE_NAMES
from gearjax.tca.family import GearFamily
from gearjax.tca.multi_pair import MultiPair
from gearjax.tca.result import SIDES, family_of, register_family

__all__ = ["EDGE_NAMES", "GearFamily", "MultiPair", "SIDES", "family_of", "register_family"]
