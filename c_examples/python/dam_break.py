#!/usr/bin/env python3
"""A small dam break driven from Python through the projfluid C API with ctypes.

Usage: dam_break.py [path/to/libprojfluid.so]
The library path may also come from the PROJFLUID_LIB environment variable; by default the
release build in target/release/ is used. The last line printed starts with
"python dam_break: ok" when the run went well.
"""

import ctypes
import os
import sys
from ctypes import POINTER, byref, c_bool, c_char_p, c_double, c_float, c_int, c_size_t
from ctypes import c_uint, c_uint32, c_uint64, c_void_p

PF_OK = 0
PF_ERROR_INVALID_ARGUMENT = 2
PF_ERROR_BUFFER_TOO_SMALL = 3


class PfParams(ctypes.Structure):
    """Mirror of PfParams in include/projfluid.h (field order and types must match)."""

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
    ]


class PfStepStats(ctypes.Structure):
    """Mirror of PfStepStats in include/projfluid.h."""

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


def load(path):
    """Loads the library and declares the signatures used here."""
    lib = ctypes.CDLL(path)
    world = c_void_p
    floats = POINTER(c_float)
    sizes = POINTER(c_size_t)
    signatures = {
        "pf_version_string": ([], c_char_p),
        "pf_last_error_message": ([], c_char_p),
        "pf_status_name": ([c_int], c_char_p),
        "pf_params_default": ([POINTER(PfParams)], c_int),
        "pf_world_create": ([POINTER(PfParams), POINTER(world)], c_int),
        "pf_world_destroy": ([world], None),
        "pf_world_add_container_box": ([world, floats, floats, c_uint], c_int),
        "pf_world_add_fluid_box": ([world, floats, sizes, floats], c_int),
        "pf_world_add_fluid_particles": ([world, floats, c_size_t], c_int),
        "pf_world_step": ([world, c_double], c_int),
        "pf_world_fluid_count": ([world, sizes], c_int),
        "pf_world_get_positions": ([world, floats, c_size_t, sizes], c_int),
        "pf_world_last_step_stats": ([world, POINTER(PfStepStats)], c_int),
    }
    for name, (args, result) in signatures.items():
        function = getattr(lib, name)
        function.argtypes = args
        function.restype = result
    return lib


def main():
    path = (sys.argv[1] if len(sys.argv) > 1 else None) or os.environ.get("PROJFLUID_LIB")
    if not path:
        here = os.path.dirname(os.path.abspath(__file__))
        path = os.path.join(here, "..", "..", "target", "release", "libprojfluid.so")
    lib = load(path)

    def check(status, what):
        if status != PF_OK:
            name = lib.pf_status_name(status).decode()
            message = lib.pf_last_error_message().decode()
            raise RuntimeError(f"{what} failed with {name}: {message}")

    def vec3(x, y, z):
        return (c_float * 3)(x, y, z)

    params = PfParams()
    check(lib.pf_params_default(byref(params)), "pf_params_default")
    params.particle_radius = 0.02
    params.displacement_tolerance = 2e-5
    world = c_void_p()
    check(lib.pf_world_create(byref(params), byref(world)), "pf_world_create")
    try:
        check(
            lib.pf_world_add_container_box(world, vec3(0, 0, 0), vec3(0.8, 0.6, 0.3), 1),
            "pf_world_add_container_box",
        )
        # The first particle centres 2r + r/4 from the walls, so that the fluid, which starts
        # at rest density, starts compressed nowhere (not even in the corners).
        count = (c_size_t * 3)(6, 10, 5)
        check(
            lib.pf_world_add_fluid_box(world, vec3(0.045, 0.045, 0.045), count, None),
            "pf_world_add_fluid_box",
        )

        # A rejected call: a NaN coordinate. The status and message explain it, and the
        # world is unchanged.
        bad = (c_float * 3)(0.1, float("nan"), 0.1)
        status = lib.pf_world_add_fluid_particles(world, bad, 1)
        assert status == PF_ERROR_INVALID_ARGUMENT, status
        print("rejected as expected:", lib.pf_last_error_message().decode())

        stats = PfStepStats()
        for _ in range(15):
            check(lib.pf_world_step(world, 0.0), "pf_world_step")
        check(lib.pf_world_last_step_stats(world, byref(stats)), "pf_world_last_step_stats")
        print(
            f"t = {stats.time:.4f} s after {stats.step_count} steps, "
            f"density error avg {stats.density_error_avg_percent:.3f} %"
        )

        n = c_size_t()
        check(lib.pf_world_fluid_count(world, byref(n)), "pf_world_fluid_count")
        needed = c_size_t()
        status = lib.pf_world_get_positions(world, None, 0, byref(needed))
        assert status == PF_ERROR_BUFFER_TOO_SMALL and needed.value == 3 * n.value
        positions = (c_float * needed.value)()
        check(
            lib.pf_world_get_positions(world, positions, needed.value, None),
            "pf_world_get_positions",
        )
        heights = positions[1::3]
        print(
            f"python dam_break: ok, projfluid {lib.pf_version_string().decode()}, "
            f"{n.value} particles, highest y = {max(heights):.3f} m, "
            f"escaped {stats.escaped_count}"
        )
    finally:
        lib.pf_world_destroy(world)


if __name__ == "__main__":
    main()
