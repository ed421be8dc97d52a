"""gearjax — differentiable gear design in JAX.

Importing gearjax enables 64-bit floats in JAX (``jax_enable_x64``): micrometre
geometry on 100 mm parts and arc-second transmission errors need float64.

Architecture (imports flow downwards only; gear families and applications import
the core, never the other way round)::

    gearjax/newton.py      implicit-differentiated, batched Newton solver
    gearjax/frames.py      4x4 homogeneous transforms from elementary motions
    gearjax/surfaces.py    autodiff differential geometry of explicit and
                           enveloped (generated) surfaces
    gearjax/kinematics.py  eigenfunction kinematics of conjugate surfaces
                           (seed 000, section 1): q, p, Phi_I, Phi_II, u1, u2,
                           u_e, u_s, SRR, K_II, R_eff, limit normal
    gearjax/gears/         gear families; involute.py: rack-generated spur and
                           helical pairs and their path-of-contact kinematics
    gearjax/gears/hypoid_blank.py, pitch_cones.py, iso23509.py
                           hypoid/spiral-bevel blank design: seed-003 tangency
                           route and ISO 23509 Methods 0/1, sensitivity Jacobian
    gearjax/cutters.py     straight-blade face-mill cutter (with edge radius)
    gearjax/machines.py    cradle-type generator settings (pytree), roll with 2C/6D,
                           Gleason No. 116 dial converter
    gearjax/gears/hypoid.py  flank grids by seed 004's algorithm (meshing,
                           face-width and face-cone conditions, continuation)
    gearjax/io.py          design files (TOML), atomic CSV/XYZ/STL exports
    gearjax/plot_flank.py  axial-plane flank figure
    gearjax/examples/      packaged design files (8/43 HFT of seed 004, ...)
    gearjax/contact.py     Hertz point contact (exact, elliptic integrals by AGM;
                           Hamrock-Brewe option; line-contact limit)
    gearjax/tribology/     lubricant (Roelands/Barus, Dowson-Higginson, Ree-Eyring),
                           film (Hamrock-Dowson, line contact), asperity
                           (Greenwood-Tripp, load sharing), friction (seed 001 mu),
                           losses (power loss, mesh efficiency, Stribeck curves)
    gearjax/plot_tribology.py  Stribeck figures
    gearjax/tca.py         tooth contact analysis of any two flanks: position and
                           normal coincidence continued by lax.scan, TE, contact
                           ellipses, multiple pairs, misalignments (dE, dP, dG, dSigma)
    gearjax/tca_involute.py  TCA adapter for involute pairs (crowning, mismatch)
    gearjax/tca_hypoid.py  TCA adapter for face-milled spiral-bevel/hypoid pairs:
                           mounting, hand check, reference contact, flank boundaries,
                           crown-gear complementary settings, V-H table
    gearjax/synthesis.py   local synthesis of a spiral-bevel/hypoid pinion through TCA
                           (least squares with exact Jacobians)
    gearjax/plot_tca.py    TE curves and contact pattern figures
    gearjax/gears/hypoid_kinematics.py  seed-000 meshing characteristics over the
                           hypoid gear flank, limits, cutter-radius study
    gearjax/optimize.py    objective -> gradient -> optax / jaxopt optimisation layer
    gearjax/plot_kinematics.py  flank field maps (u_e, SRR, R_eff)
    gearjax/errors.py      exception types and boundary validation helpers
    gearjax/cli.py         the ``gearjax`` command

Units inside the library: mm, N, s, rad.  Degrees appear only at the boundary
(CLI flags, design files, printed tables).
"""

import jax as _jax

_jax.config.update("jax_enable_x64", True)

__version__ = "0.1.0"

__all__ = ["__version__"]
