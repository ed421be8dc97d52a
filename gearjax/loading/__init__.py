"""The loaded chain, on top of the TCA and tribology: materials, tooth compliance
(``tooth_compliance``, ``pair_stiffness``), load sharing among the tooth pairs
(``loaded_contact``), and mesh efficiency (``mesh_efficiency``, its inputs
``efficiency_inputs`` and its checks ``efficiency_checks``).  Public entry points:
:func:`gearjax.mesh_efficiency` and :func:`gearjax.efficiency_function`; the names below
are the settings and ranges they accept (the command line's help and checks use them).
"""

from gearjax.loading.loaded_contact import COMPLIANCE_MODELS
from gearjax.loading.efficiency_inputs import RPM_RANGE, TORQUE_RANGE_NM
from gearjax.loading.materials import E_PRIME_RANGE_MPA, STEEL
from gearjax.loading.mesh_efficiency import COMPLIANCE_HELP, DEFAULT_COMPLIANCE

__all__ = ["COMPLIANCE_MODELS", "COMPLIANCE_HELP", "DEFAULT_COMPLIANCE", "RPM_RANGE",
           "TORQUE_RANGE_NM", "E_PRIME_RANGE_MPA", "STEEL"]
