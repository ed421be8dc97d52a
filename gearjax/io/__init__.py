"""File formats shared by every gear family, apart from the chain: atomic writes and
strict JSON (:mod:`~gearjax.io.files`), TOML and the value checks of design-file
readers, packaged examples (:mod:`~gearjax.io.toml`), the design-file registry
(:mod:`~gearjax.io.designs`), flank exports (:mod:`~gearjax.io.exports`), measured flank grids
(:mod:`~gearjax.io.measured_grid`).

A leaf: nothing here imports a gear family or the chain.  Each family reads its own
design files (for instance :mod:`gearjax.gears.hypoid.design_file`) with
:func:`read_toml`, :func:`check_keys` and :func:`require_key`, and registers its
``[design] kind`` with :func:`register_design_kind`.
"""

from gearjax.io.files import (WriteError, atomic_write, atomic_write_figure, check_output_path,
                              dumps_json, figure_bytes, finite_json)
from gearjax.io.toml import (EXAMPLE_ALIASES, check_integer, check_keys, check_number,
                             check_string, dumps_toml, example_path, is_number, list_examples,
                             read_toml, require_key)
from gearjax.io.designs import (DesignFileMixin, design_from_dict, design_kinds, load_design,
                                register_design_kind)
from gearjax.io.exports import (FlankGrid, UnconvergedExportError, check_grid_converged,
                                flank_triangles, tooth_mesh, write_csv, write_flank,
                                write_stl_flank, write_stl_tooth, write_xyz)
from gearjax.io.measured_grid import (MeasuredGrid, check_on_reference, grid_heights,
                                      parse_grid_size, read_measured_grid, write_reference_grid)

__all__ = ["read_toml", "check_keys", "require_key", "check_number", "check_integer",
           "check_string", "is_number", "dumps_toml", "list_examples", "EXAMPLE_ALIASES",
           "example_path", "atomic_write", "atomic_write_figure", "figure_bytes",
           "check_output_path", "WriteError", "finite_json", "dumps_json",
           "write_csv", "write_xyz", "write_stl_flank",
           "write_stl_tooth", "tooth_mesh", "flank_triangles", "write_flank",
           "register_design_kind", "design_kinds", "design_from_dict", "load_design",
           "DesignFileMixin", "FlankGrid", "UnconvergedExportError", "check_grid_converged",
           "MeasuredGrid", "read_measured_grid", "write_reference_grid", "check_on_reference",
           "parse_grid_size", "grid_heights"]
