"""The C library: finding and loading it, mirrors of its structs, its functions' signatures.

Everything here mirrors ``include/projfluid.h`` (``PF_ABI_VERSION`` 7); the rest of the
package calls the C API only through :data:`lib`. ctypes releases the GIL during every
foreign call, so long calls such as ``pf_world_advance`` let other Python threads run.
"""

from __future__ import annotations

import ctypes
import os
import sys
from ctypes import (
    POINTER,
    c_bool,
    c_char,
    c_char_p,
    c_double,
    c_float,
    c_int,
    c_size_t,
    c_uint,
    c_uint16,
    c_uint32,
    c_uint64,
    c_void_p,
)
from pathlib import Path
from typing import Any

#: The binary interface these declarations were written for (``PF_ABI_VERSION``).
ABI_VERSION = 7


def library_file_name() -> str:
    """The file name of the shared library on this platform."""
    if sys.platform == "darwin":
        return "libprojfluid.dylib"
    if sys.platform == "win32":
        return "projfluid.dll"
    return "libprojfluid.so"


def library_path() -> Path:
    """The shared library this package loads: ``$PROJFLUID_LIB`` when set (for developers
    running the package from a checkout), otherwise the copy bundled inside the package."""
    override = os.environ.get("PROJFLUID_LIB")
    if override:
        return Path(override)
    return Path(__file__).resolve().parent / library_file_name()


class PfParams(ctypes.Structure):
    """Mirror of ``PfParams`` (field order and types as in the header)."""

    _fields_ = [
        ("particle_radius", c_double),
        ("rest_density", c_double),
        ("mass_factor", c_double),
        ("stiffness", c_double),
        ("gravity", c_double * 3),
        ("solver", c_int),
        ("omega2_rule", c_int),
        ("chebyshev_rho", c_double),
        ("chebyshev_delay", c_uint32),
        ("chebyshev_gamma", c_double),
        ("chebyshev_auto_rho", c_uint32),
        ("projection_weight", c_int),
        ("density_tolerance", c_double),
        ("displacement_tolerance", c_double),
        ("warm_start", c_double),
        ("coarse_correction", c_uint32),
        ("min_outer_iterations", c_uint32),
        ("max_outer_iterations", c_uint32),
        ("cfl_factor", c_double),
        ("dt_min", c_double),
        ("dt_max", c_double),
        ("dt_initial", c_double),
        ("viscosity", c_double),
        ("threads", c_uint32),
        ("kinematic_viscosity", c_double),
        ("no_slip", c_uint32),
        ("backend", c_uint32),
        ("vorticity_confinement", c_double),
        ("surface_tension", c_double),
        ("wall_adhesion", c_double),
    ]


class PfStepStats(ctypes.Structure):
    """Mirror of ``PfStepStats``."""

    _fields_ = [
        ("step_count", c_uint64),
        ("time", c_double),
        ("dt", c_double),
        ("outer_iterations", c_size_t),
        ("inner_iterations", c_size_t),
        ("hit_max_iterations", c_bool),
        ("last_displacement", c_double),
        ("density_error_avg_percent", c_double),
        ("density_error_max_percent", c_double),
        ("escaped_count", c_size_t),
        ("nan_count", c_size_t),
    ]


class PfTransform(ctypes.Structure):
    """Mirror of ``PfTransform``."""

    _fields_ = [
        ("scale", c_double * 3),
        ("rotate_deg", c_double * 3),
        ("translate", c_double * 3),
    ]


class PfPose(ctypes.Structure):
    """Mirror of ``PfPose``."""

    _fields_ = [("position", c_double * 3), ("rotation", c_double * 4)]


_world = c_void_p
_floats = POINTER(c_float)
_doubles = POINTER(c_double)
_sizes = POINTER(c_size_t)
_u16s = POINTER(c_uint16)
_u32s = POINTER(c_uint32)
_u64s = POINTER(c_uint64)
_params = POINTER(PfParams)
_pose = POINTER(PfPose)
_transform = POINTER(PfTransform)
_status = c_int

#: Every function of the header this package uses: (argument types, result type).
SIGNATURES: dict[str, tuple[list[Any], Any]] = {
    # status, versions, parameters
    "pf_last_error_message": ([], c_char_p),
    "pf_status_name": ([c_int], c_char_p),
    "pf_version_string": ([], c_char_p),
    "pf_abi_version": ([], c_uint32),
    "pf_params_default": ([_params], _status),
    "pf_params_calm": ([_params], _status),
    "pf_params_validate": ([_params], _status),
    "pf_transform_identity": ([_transform], _status),
    "pf_pose_identity": ([_pose], _status),
    # creating and filling a world
    "pf_world_create": ([_params, POINTER(_world)], _status),
    "pf_world_create_from_scene": ([c_char_p, POINTER(_world)], _status),
    "pf_world_destroy": ([_world], None),
    "pf_world_add_fluid_particles": ([_world, _floats, c_size_t], _status),
    "pf_world_add_fluid_particles_with_velocities": (
        [_world, _floats, _floats, c_size_t],
        _status,
    ),
    "pf_world_add_fluid_box": ([_world, _floats, _sizes, _floats], _status),
    "pf_world_add_boundary_particles": ([_world, _floats, c_size_t], _status),
    "pf_world_add_container_box": ([_world, _floats, _floats, c_uint], _status),
    "pf_world_add_container_box_spaced": ([_world, _floats, _floats, c_uint, c_float], _status),
    "pf_world_add_container_field": ([_world, _floats, _floats], _status),
    "pf_world_add_mesh": ([_world, _floats, c_size_t, _u32s, c_size_t], _status),
    "pf_world_add_mesh_transformed": (
        [_world, _floats, c_size_t, _u32s, c_size_t, _transform],
        _status,
    ),
    "pf_world_add_obj": ([_world, c_char_p, _transform], _status),
    # emitters, sinks, the domain, removal
    "pf_world_add_emitter_disc": (
        [_world, _doubles, _doubles, c_double, c_double, c_double, _sizes],
        _status,
    ),
    "pf_world_add_emitter_rect": (
        [_world, _doubles, _doubles, c_double, c_double, c_double, c_double, _sizes],
        _status,
    ),
    "pf_world_add_sink": ([_world, _doubles, _doubles, _sizes], _status),
    "pf_world_set_domain": ([_world, _doubles, _doubles], _status),
    "pf_world_clear_domain": ([_world], _status),
    "pf_world_remove_particles": ([_world, _u64s, c_size_t, _sizes], _status),
    "pf_world_removed_count": ([_world, _u64s], _status),
    "pf_world_emitted_count": ([_world, _u64s], _status),
    # materials
    "pf_world_add_material": ([_world, c_double, _u16s], _status),
    "pf_world_set_fluid_material": ([_world, c_uint16], _status),
    "pf_world_fluid_material": ([_world, _u16s], _status),
    "pf_world_material_count": ([_world, _sizes], _status),
    "pf_world_get_material_rest_density": ([_world, c_uint16, _doubles], _status),
    "pf_world_set_material_kinematic_viscosity": ([_world, c_uint16, c_double], _status),
    "pf_world_get_material_kinematic_viscosity": ([_world, c_uint16, _doubles], _status),
    "pf_world_set_material_surface_tension": ([_world, c_uint16, c_double], _status),
    "pf_world_get_material_surface_tension": ([_world, c_uint16, _doubles], _status),
    "pf_world_get_materials": ([_world, _u16s, c_size_t, _sizes], _status),
    # stepping
    "pf_world_step": ([_world, c_double], _status),
    "pf_world_advance": ([_world, c_double], _status),
    "pf_world_relax": ([_world, c_double, c_double], _status),
    # reading
    "pf_world_fluid_count": ([_world, _sizes], _status),
    "pf_world_last_added_count": ([_world, _sizes], _status),
    "pf_world_boundary_count": ([_world, _sizes], _status),
    "pf_world_time": ([_world, _doubles], _status),
    "pf_world_get_params": ([_world, _params], _status),
    "pf_world_last_step_stats": ([_world, POINTER(PfStepStats)], _status),
    "pf_world_get_positions": ([_world, _floats, c_size_t, _sizes], _status),
    "pf_world_get_velocities": ([_world, _floats, c_size_t, _sizes], _status),
    "pf_world_get_densities": ([_world, _floats, c_size_t, _sizes], _status),
    "pf_world_get_ids": ([_world, _u64s, c_size_t, _sizes], _status),
    "pf_world_positions_hash": ([_world, POINTER(c_char), c_size_t, _sizes], _status),
    # rigid bodies
    "pf_world_add_body_box": ([_world, c_int, _doubles, c_double, _pose, _sizes], _status),
    "pf_world_add_body_sphere": (
        [_world, c_int, c_double, c_double, _pose, _sizes],
        _status,
    ),
    "pf_world_add_body_cylinder": (
        [_world, c_int, c_double, c_double, c_double, _pose, _sizes],
        _status,
    ),
    "pf_world_add_body_mesh": (
        [_world, c_int, _floats, c_size_t, _u32s, c_size_t, c_double, _pose, _sizes],
        _status,
    ),
    "pf_world_body_count": ([_world, _sizes], _status),
    "pf_body_set_pose": ([_world, c_size_t, _pose], _status),
    "pf_body_set_velocity": ([_world, c_size_t, _doubles, _doubles], _status),
    "pf_body_set_target_pose": ([_world, c_size_t, _pose], _status),
    "pf_body_get_kind": ([_world, c_size_t, POINTER(c_int)], _status),
    "pf_body_get_pose": ([_world, c_size_t, _pose], _status),
    "pf_body_get_velocity": ([_world, c_size_t, _doubles, _doubles], _status),
    "pf_body_get_centre_of_mass": ([_world, c_size_t, _doubles], _status),
    "pf_body_get_force_torque": ([_world, c_size_t, _doubles, _doubles], _status),
    "pf_world_get_wall_force": ([_world, _doubles], _status),
}


def load(path: Path) -> ctypes.CDLL:
    """Loads the library at ``path``, declares :data:`SIGNATURES` and checks the ABI version.

    Raises :class:`ImportError` when the file is missing, cannot be loaded, lacks a function
    or implements another ABI version.
    """
    if not path.exists():
        raise ImportError(
            f"the projfluid C library {path} is missing: install the package with "
            "`pip install ./python` from a projfluid checkout, or set PROJFLUID_LIB to a "
            f"built {library_file_name()}"
        )
    try:
        library = ctypes.CDLL(str(path))
    except OSError as e:
        raise ImportError(f"cannot load the projfluid C library {path}: {e}") from e
    for name, (arguments, result) in SIGNATURES.items():
        try:
            function = getattr(library, name)
        except AttributeError as e:
            raise ImportError(f"{path} has no function {name}; is it an older build?") from e
        function.argtypes = arguments
        function.restype = result
    found = library.pf_abi_version()
    if found != ABI_VERSION:
        raise ImportError(
            f"{path} implements ABI version {found}, this package was written for {ABI_VERSION}"
        )
    return library


#: The loaded C library.
lib: ctypes.CDLL = load(library_path())
