/* Every kind of rejected call: each must return the right status, leave a message naming the
 * function, and leave the world exactly as it was (counts, time, positions bit for bit);
 * the next valid call must work and clear the message. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"

static void same(const PfWorld *w, const WorldSnapshot *before, int line) {
    WorldSnapshot now = world_snapshot(w);
    if (!same_world(&now, before)) {
        fprintf(stderr, "misuse.c:%d: a rejected call changed the world\n", line);
        exit(1);
    }
}

/* The message of the last REJECT, kept because the checks after it clear the library's. */
static char last_msg[512];

/* A rejected call on world `w`: expected status, a message, and no change. */
#define REJECT(w, expected, call)                                                         \
    do {                                                                                  \
        WorldSnapshot before_ = world_snapshot(w);                                        \
        EXPECT(expected, call);                                                           \
        snprintf(last_msg, sizeof last_msg, "%s", pf_last_error_message());               \
        same(w, &before_, __LINE__);                                                      \
        rejected++;                                                                       \
    } while (0)

static int rejected = 0;

static void bad_params(PfParams p, const char *field) {
    PfWorld *w = (PfWorld *)&p; /* must be overwritten with NULL */
    EXPECT(PF_ERROR_INVALID_ARGUMENT, pf_params_validate(&p));
    if (strstr(pf_last_error_message(), field) == NULL)
        FAIL("the message does not name %s", field);
    EXPECT(PF_ERROR_INVALID_ARGUMENT, pf_world_create(&p, &w));
    if (strstr(pf_last_error_message(), field) == NULL)
        FAIL("the message does not name %s", field);
    CHECK(w == NULL);
    /* pf_params_calm rejects them too and leaves them as they were. */
    PfParams calm = p;
    EXPECT(PF_ERROR_INVALID_ARGUMENT, pf_params_calm(&calm));
    if (strstr(pf_last_error_message(), field) == NULL)
        FAIL("the message does not name %s", field);
    CHECK(calm.projection_weight == p.projection_weight);
    CHECK(memcmp(&calm.displacement_tolerance, &p.displacement_tolerance, sizeof(double)) == 0);
    CHECK(memcmp(&calm.chebyshev_rho, &p.chebyshev_rho, sizeof(double)) == 0);
    CHECK(memcmp(&calm.chebyshev_gamma, &p.chebyshev_gamma, sizeof(double)) == 0);
    CHECK(calm.chebyshev_auto_rho == p.chebyshev_auto_rho);
    CHECK(calm.coarse_correction == p.coarse_correction);
    CHECK(memcmp(&calm.kinematic_viscosity, &p.kinematic_viscosity, sizeof(double)) == 0);
    CHECK(calm.no_slip == p.no_slip);
    CHECK(calm.backend == p.backend);
    rejected += 3;
}

int main(void) {
    PfParams params;
    OK(pf_params_default(&params));
    params.threads = 2;

    /* --- Invalid parameters. --- */
    PfParams p = params;
    p.particle_radius = 0.0;
    bad_params(p, "particle_radius");
    p = params;
    p.particle_radius = NAN;
    bad_params(p, "particle_radius");
    p = params;
    p.particle_radius = 1e-200; /* the particle mass underflows to zero */
    bad_params(p, "particle_radius");
    p = params;
    p.stiffness = -1.0;
    bad_params(p, "stiffness");
    p = params;
    p.gravity[2] = INFINITY;
    bad_params(p, "gravity[2]");
    p = params;
    p.dt_min = 0.1;
    bad_params(p, "dt_min");
    p = params;
    p.dt_max = 2.0; /* more than the longest step a world takes (1 s) */
    bad_params(p, "dt_max");
    p = params;
    p.dt_initial = 1.5;
    bad_params(p, "dt_initial");
    p = params;
    p.chebyshev_rho = 1.0;
    bad_params(p, "rho");
    p = params;
    p.chebyshev_delay = 0;
    bad_params(p, "delay");
    p = params;
    p.chebyshev_gamma = 0.0;
    bad_params(p, "gamma");
    p = params;
    p.max_outer_iterations = 0;
    bad_params(p, "max_outer_iterations");
    p = params;
    p.viscosity = 2.0;
    bad_params(p, "viscosity");
    p = params;
    p.threads = 5000;
    bad_params(p, "threads");
    p = params;
    p.solver = (PfSolver)7;
    bad_params(p, "solver");
    p = params;
    p.omega2_rule = (PfOmega2Rule)9;
    bad_params(p, "omega2_rule");
    p = params;
    p.projection_weight = (PfProjectionWeight)-1;
    bad_params(p, "projection_weight");
    p = params;
    p.chebyshev_auto_rho = 2;
    bad_params(p, "chebyshev_auto_rho");
    p = params;
    p.coarse_correction = 2;
    bad_params(p, "coarse_correction");
    p = params;
    p.kinematic_viscosity = NAN;
    bad_params(p, "params->kinematic_viscosity must be finite and not negative");
    p = params;
    p.kinematic_viscosity = -1e-6;
    bad_params(p, "params->kinematic_viscosity must be finite and not negative");
    p = params;
    p.kinematic_viscosity = INFINITY;
    bad_params(p, "params->kinematic_viscosity must be finite and not negative");
    p = params;
    p.no_slip = 2;
    bad_params(p, "params->no_slip must be 0 or 1, got 2");
    p = params;
    p.vorticity_confinement = NAN;
    bad_params(p, "params->vorticity_confinement must lie in [0, 10]");
    p = params;
    p.vorticity_confinement = -0.5;
    bad_params(p, "params->vorticity_confinement must lie in [0, 10]");
    p = params;
    p.backend = 2;
    bad_params(p, "params->backend must be PF_BACKEND_CPU (0) or PF_BACKEND_GPU (1), got 2");
    p = params;
    p.backend = UINT32_MAX;
    bad_params(p, "params->backend must be PF_BACKEND_CPU (0) or PF_BACKEND_GPU (1), got 4294967295");

    /* The GPU backend is not in this build (the tests' library is built without the `gpu`
       feature): the value is valid, but no world is made, and the message names the backend
       and the missing feature. pf_world_create_from_scene refuses a scene for the GPU the
       same way (src/ffi/scene.rs). */
    p = params;
    p.backend = PF_BACKEND_GPU;
    OK(pf_params_validate(&p));
    {
        PfWorld *none = (PfWorld *)&p; /* must be overwritten with NULL */
        EXPECT(PF_ERROR_INVALID_ARGUMENT, pf_world_create(&p, &none));
        CHECK(strcmp(pf_last_error_message(),
                     "pf_world_create: backend gpu: not available: this build of projfluid has "
                     "no `gpu` feature") == 0);
        CHECK(none == NULL);
        rejected++;
    }

    /* --- NULL pointers outside a world. --- */
    PfWorld *w = NULL;
    EXPECT(PF_ERROR_NULL_POINTER, pf_params_default(NULL));
    EXPECT(PF_ERROR_NULL_POINTER, pf_params_validate(NULL));
    EXPECT(PF_ERROR_NULL_POINTER, pf_params_calm(NULL));
    EXPECT(PF_ERROR_NULL_POINTER, pf_world_create(&params, NULL));
    w = (PfWorld *)&params;
    EXPECT(PF_ERROR_NULL_POINTER, pf_world_create(NULL, &w));
    CHECK(w == NULL);
    rejected += 5;

    /* --- An empty world cannot step; advancing or relaxing by 0 is fine. --- */
    OK(pf_world_create(&params, &w));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_step(w, 0.0));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_advance(w, 0.01));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_relax(w, 0.01, 1.0));
    OK(pf_world_advance(w, 0.0));
    OK(pf_world_relax(w, 0.0, 1.0));

    /* --- A valid world to misuse. --- */
    const float lo[3] = {0.0f, 0.0f, 0.0f}, hi[3] = {0.3f, 0.3f, 0.3f};
    OK(pf_world_add_container_box(w, lo, hi, 1));
    const float start[3] = {0.05f, 0.05f, 0.05f};
    const size_t count[3] = {3, 3, 3};
    OK(pf_world_add_fluid_box(w, start, count, NULL));
    OK(pf_world_step(w, 0.0));
    size_t n = 0;
    OK(pf_world_fluid_count(w, &n));
    CHECK(n == 27);

    /* A small closed mesh, a tetrahedron of 8 cm sides beside the fluid. */
    float mesh_v[12] = {0.2f, 0.02f, 0.2f, 0.28f, 0.02f, 0.2f,
                        0.2f, 0.1f,  0.2f, 0.2f,  0.02f, 0.28f};
    uint32_t mesh_i[12] = {0, 1, 2, 0, 1, 3, 0, 2, 3, 1, 2, 3};

    /* NULL world, for every function that takes one. */
    const float xyz[6] = {0.1f, 0.1f, 0.1f, 0.2f, 0.1f, 0.1f};
    float buf[3 * 27 + 8];
    size_t needed = 0, sz = 0;
    double t = 0.0;
    PfStepStats st;
    PfParams back;
    char hash[65];
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_fluid_particles(NULL, xyz, 2));
    REJECT(w, PF_ERROR_NULL_POINTER,
           pf_world_add_fluid_particles_with_velocities(NULL, xyz, xyz, 2));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_fluid_box(NULL, start, count, NULL));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_boundary_particles(NULL, xyz, 2));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_container_box(NULL, lo, hi, 1));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_mesh(NULL, mesh_v, 4, mesh_i, 4));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_step(NULL, 0.0));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_advance(NULL, 0.01));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_relax(NULL, 0.01, 1.0));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_fluid_count(NULL, &sz));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_boundary_count(NULL, &sz));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_time(NULL, &t));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_params(NULL, &back));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_last_step_stats(NULL, &st));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_positions(NULL, buf, 81, &needed));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_velocities(NULL, buf, 81, &needed));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_densities(NULL, buf, 27, &needed));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_positions_hash(NULL, hash, 65, &needed));

    /* NULL buffers and outputs. */
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_fluid_particles(w, NULL, 2));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_boundary_particles(w, NULL, 2));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_fluid_box(w, NULL, count, NULL));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_fluid_box(w, start, NULL, NULL));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_container_box(w, NULL, hi, 1));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_container_box(w, lo, NULL, 1));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_mesh(w, NULL, 4, mesh_i, 4));
    CHECK(strstr(last_msg, "vertices") != NULL);
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_mesh(w, mesh_v, 4, NULL, 4));
    CHECK(strstr(last_msg, "indices") != NULL);
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_fluid_count(w, NULL));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_boundary_count(w, NULL));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_time(w, NULL));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_params(w, NULL));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_last_step_stats(w, NULL));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_positions(w, NULL, 81, &needed));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_velocities(w, NULL, 81, NULL));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_densities(w, NULL, 27, NULL));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_positions_hash(w, NULL, 65, NULL));

    /* Short buffers: the size needed is reported and the buffer is left untouched. */
    for (size_t i = 0; i < sizeof buf / sizeof *buf; i++) buf[i] = -7.0f;
    needed = 0;
    REJECT(w, PF_ERROR_BUFFER_TOO_SMALL, pf_world_get_positions(w, buf, 80, &needed));
    CHECK(needed == 81);
    REJECT(w, PF_ERROR_BUFFER_TOO_SMALL, pf_world_get_velocities(w, buf, 3, &needed));
    CHECK(needed == 81);
    REJECT(w, PF_ERROR_BUFFER_TOO_SMALL, pf_world_get_densities(w, buf, 26, &needed));
    CHECK(needed == 27);
    REJECT(w, PF_ERROR_BUFFER_TOO_SMALL, pf_world_positions_hash(w, hash, 64, &needed));
    CHECK(needed == 65);
    for (size_t i = 0; i < sizeof buf / sizeof *buf; i++) CHECK(buf[i] == -7.0f);
    /* A larger buffer than needed is fine; the tail stays untouched. */
    OK(pf_world_get_positions(w, buf, sizeof buf / sizeof *buf, &needed));
    CHECK(needed == 81 && buf[81] == -7.0f && buf[0] != -7.0f);

    /* Non-finite coordinates, with the index named. */
    float nan_xyz[6] = {0.1f, 0.1f, 0.1f, 0.2f, NAN, 0.1f};
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_fluid_particles(w, nan_xyz, 2));
    CHECK(strstr(last_msg, "xyz[1]") != NULL);
    float inf_v[6] = {0.0f, 0.0f, 0.0f, INFINITY, 0.0f, 0.0f};
    REJECT(w, PF_ERROR_INVALID_ARGUMENT,
           pf_world_add_fluid_particles_with_velocities(w, xyz, inf_v, 2));
    CHECK(strstr(last_msg, "velocities[1]") != NULL);
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_boundary_particles(w, nan_xyz, 2));
    const float nan3[3] = {0.0f, NAN, 0.0f}, inf3[3] = {-INFINITY, 0.0f, 0.0f};
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_fluid_box(w, nan3, count, NULL));
    CHECK(strstr(last_msg, "start must be finite") != NULL);
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_fluid_box(w, start, count, inf3));
    CHECK(strstr(last_msg, "velocity must be finite") != NULL);
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_container_box(w, inf3, hi, 1));
    CHECK(strstr(last_msg, "min must be finite") != NULL);
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_container_box(w, lo, nan3, 1));
    CHECK(strstr(last_msg, "max must be finite") != NULL);

    /* Zero and absurd counts. */
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_fluid_particles(w, xyz, 0));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_boundary_particles(w, xyz, 0));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_fluid_particles(w, xyz, SIZE_MAX));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_fluid_particles(w, xyz, SIZE_MAX / 3 + 1));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_boundary_particles(w, xyz, SIZE_MAX / 2));
    const size_t zero[3] = {4, 0, 4}, overflow[3] = {SIZE_MAX, SIZE_MAX, 2},
                 huge[3] = {100000, 100000, 100000};
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_fluid_box(w, start, zero, NULL));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_fluid_box(w, start, overflow, NULL));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_fluid_box(w, start, huge, NULL));
    const float far[3] = {1000.0f, 1000.0f, 1000.0f};
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_container_box(w, lo, far, 1));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_container_box(w, hi, lo, 1)); /* inverted */
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_container_box(w, lo, hi, 0));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_container_box(w, lo, hi, 4));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_container_box_spaced(NULL, lo, hi, 1, 0.025f));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_container_box_spaced(w, NULL, hi, 1, 0.025f));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_container_box_spaced(w, lo, hi, 1, NAN));
    CHECK(strstr(last_msg, "spacing must be from r/4 to 2r") != NULL);
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_container_box_spaced(w, lo, hi, 1, 0.0f));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_container_box_spaced(w, lo, hi, 1, 0.06f));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_container_box_spaced(w, lo, hi, 0, 0.025f));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_container_field(NULL, lo, hi));
    REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_container_field(w, lo, NULL));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_container_field(w, lo, nan3));
    CHECK(strstr(last_msg, "max must be finite") != NULL);
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_container_field(w, hi, lo)); /* inverted */
    CHECK(strstr(last_msg, "two particle spacings") != NULL);
    const float farther[3] = {5000.0f, 1.0f, 1.0f}; /* 2e5 radii */
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_container_field(w, lo, farther));
    CHECK(strstr(last_msg, "too large") != NULL);

    /* Bad meshes: zero and absurd counts, bad indices and vertices, degenerate triangles,
     * a mesh far too large for the particle radius. */
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_mesh(w, mesh_v, 0, mesh_i, 4));
    CHECK(strstr(last_msg, "vertex_count") != NULL);
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_mesh(w, mesh_v, 4, mesh_i, 0));
    CHECK(strstr(last_msg, "triangle_count") != NULL);
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_mesh(w, NULL, 0, NULL, 0));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_mesh(w, mesh_v, SIZE_MAX, mesh_i, 4));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_mesh(w, mesh_v, 4, mesh_i, SIZE_MAX / 3));
    mesh_i[7] = 4; /* triangle 2, corner 1: only vertices 0-3 exist */
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_mesh(w, mesh_v, 4, mesh_i, 4));
    CHECK(strstr(last_msg, "triangles[2][1]") != NULL && strstr(last_msg, "got 4") != NULL);
    mesh_i[7] = UINT32_MAX;
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_mesh(w, mesh_v, 4, mesh_i, 4));
    CHECK(strstr(last_msg, "triangles[2][1]") != NULL);
    mesh_i[7] = 2;
    mesh_v[10] = NAN; /* vertex 3, y */
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_mesh(w, mesh_v, 4, mesh_i, 4));
    CHECK(strstr(last_msg, "vertices[3]") != NULL && strstr(last_msg, "finite") != NULL);
    mesh_v[10] = INFINITY;
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_mesh(w, mesh_v, 4, mesh_i, 4));
    CHECK(strstr(last_msg, "vertices[3]") != NULL);
    mesh_v[10] = 0.02f;
    mesh_i[4] = 0; /* triangle 1 becomes {0, 0, 3} */
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_mesh(w, mesh_v, 4, mesh_i, 4));
    CHECK(strstr(last_msg, "triangles[1]") != NULL && strstr(last_msg, "degenerate") != NULL);
    mesh_i[4] = 1;
    const float line_v[9] = {0.2f, 0.02f, 0.2f, 0.24f, 0.02f, 0.2f, 0.28f, 0.02f, 0.2f};
    const uint32_t line_i[3] = {0, 1, 2}; /* collinear corners: zero area */
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_mesh(w, line_v, 3, line_i, 1));
    CHECK(strstr(last_msg, "triangles[0]") != NULL && strstr(last_msg, "collinear") != NULL);
    const float huge_v[9] = {0.0f, 0.0f, 0.0f, 1000.0f, 0.0f, 0.0f, 0.0f, 0.0f, 1000.0f};
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_mesh(w, huge_v, 3, line_i, 1));
    CHECK(strstr(last_msg, "mesh") != NULL);

    /* Bad step sizes and durations. */
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_step(w, NAN));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_step(w, INFINITY));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_step(w, -INFINITY));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_step(w, 2.0));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_advance(w, -0.1));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_advance(w, NAN));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_advance(w, INFINITY));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_relax(w, -0.1, 1.0));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_relax(w, 0.01, -1.0));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_relax(w, 0.01, NAN));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_relax(w, 0.01, INFINITY));
    /* Durations between 0 and dt_min (1e-4 s) would not move the clock reliably. */
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_advance(w, 1e-13));
    CHECK(strstr(last_msg, "dt_min") != NULL);
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_advance(w, 1e-300));
    REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_relax(w, 5e-5, 1.0));

    /* --- Materials. --- */
    {
        uint16_t id = 77, material = 77;
        size_t count = 0;
        double rho0 = -1.0;
        uint16_t mats[27 + 4];
        OK(pf_world_add_material(w, 1500.0, &id));
        CHECK(id == 1);
        OK(pf_world_material_count(w, &count));
        CHECK(count == 2);
        id = 77;
        /* NULL world, for every material function. */
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_material(NULL, 1200.0, &id));
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_set_fluid_material(NULL, 1));
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_fluid_material(NULL, &material));
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_material_count(NULL, &count));
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_material_rest_density(NULL, 0, &rho0));
        REJECT(w, PF_ERROR_NULL_POINTER,
               pf_world_set_material_kinematic_viscosity(NULL, 0, 1e-3));
        REJECT(w, PF_ERROR_NULL_POINTER,
               pf_world_get_material_kinematic_viscosity(NULL, 0, &rho0));
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_set_material_surface_tension(NULL, 0, 0.07));
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_material_surface_tension(NULL, 0, &rho0));
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_materials(NULL, mats, 27, &needed));
        CHECK(strstr(last_msg, "world must not be NULL") != NULL);
        /* NULL outputs: a material is not added for want of a place to put its id. */
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_add_material(w, 1200.0, NULL));
        CHECK(strcmp(last_msg, "pf_world_add_material: out must not be NULL") == 0);
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_fluid_material(w, NULL));
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_material_count(w, NULL));
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_material_rest_density(w, 0, NULL));
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_material_kinematic_viscosity(w, 0, NULL));
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_material_surface_tension(w, 0, NULL));
        REJECT(w, PF_ERROR_NULL_POINTER, pf_world_get_materials(w, NULL, 27, NULL));
        CHECK(strstr(last_msg, "out must not be NULL") != NULL);
        /* Rest densities that are not finite or lie outside 0.1 to 10 times the world's
           (100 to 10000 kg/m^3 here), the argument and the range named. */
        const double bad_densities[] = {NAN, INFINITY, -INFINITY, 0.0, -1000.0, 99.9, 10000.5,
                                        1e300};
        for (size_t i = 0; i < sizeof bad_densities / sizeof *bad_densities; i++) {
            REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_add_material(w, bad_densities[i], &id));
            CHECK(strstr(last_msg, "pf_world_add_material: rest_density must be between 100 and "
                                   "10000 kg/m³") != NULL);
        }
        /* Unknown material ids, the range named. */
        REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_set_fluid_material(w, 2));
        CHECK(strstr(last_msg, "material must name one of the world's 2 materials (0 to 1), "
                               "got 2") != NULL);
        REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_set_fluid_material(w, UINT16_MAX));
        REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_get_material_rest_density(w, 2, &rho0));
        CHECK(strstr(last_msg, "material must name one of the world's 2 materials (0 to 1), "
                               "got 2") != NULL);
        REJECT(w, PF_ERROR_INVALID_ARGUMENT,
               pf_world_get_material_rest_density(w, UINT16_MAX, &rho0));
        REJECT(w, PF_ERROR_INVALID_ARGUMENT,
               pf_world_get_material_kinematic_viscosity(w, 2, &rho0));
        REJECT(w, PF_ERROR_INVALID_ARGUMENT,
               pf_world_set_material_kinematic_viscosity(w, 2, 1e-3));
        /* Viscosities that are negative or not finite, the argument named. */
        const double bad_viscosities[] = {NAN, INFINITY, -1e-3};
        for (size_t i = 0; i < sizeof bad_viscosities / sizeof *bad_viscosities; i++) {
            REJECT(w, PF_ERROR_INVALID_ARGUMENT,
                   pf_world_set_material_kinematic_viscosity(w, 1, bad_viscosities[i]));
            CHECK(strstr(last_msg, "pf_world_set_material_kinematic_viscosity: "
                                   "kinematic_viscosity must be finite") != NULL);
        }
        /* Surface tensions that are negative or not finite, or of an unknown material, the
           argument named; the surface tension stays unset. */
        const double bad_tensions[] = {NAN, INFINITY, -0.07};
        for (size_t i = 0; i < sizeof bad_tensions / sizeof *bad_tensions; i++) {
            REJECT(w, PF_ERROR_INVALID_ARGUMENT,
                   pf_world_set_material_surface_tension(w, 1, bad_tensions[i]));
            CHECK(strstr(last_msg, "pf_world_set_material_surface_tension: "
                                   "surface_tension must be finite and not negative") != NULL);
        }
        REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_set_material_surface_tension(w, 2, 0.07));
        CHECK(strstr(last_msg, "material must name one of the world's 2 materials (0 to 1), "
                               "got 2") != NULL);
        REJECT(w, PF_ERROR_INVALID_ARGUMENT, pf_world_get_material_surface_tension(w, 2, &rho0));
        double unset = -1.0;
        OK(pf_world_get_material_surface_tension(w, 1, &unset));
        CHECK(unset == 0.0);
        /* A short buffer: the size needed is reported and the buffer is left untouched. */
        for (size_t i = 0; i < sizeof mats / sizeof *mats; i++) mats[i] = 0xabcd;
        needed = 0;
        REJECT(w, PF_ERROR_BUFFER_TOO_SMALL, pf_world_get_materials(w, mats, 26, &needed));
        CHECK(needed == 27);
        REJECT(w, PF_ERROR_BUFFER_TOO_SMALL, pf_world_get_materials(w, mats, 0, NULL));
        for (size_t i = 0; i < sizeof mats / sizeof *mats; i++) CHECK(mats[i] == 0xabcd);
        /* None of that changed the materials, the choice, or the outputs. */
        CHECK(id == 77 && material == 77 && rho0 == -1.0);
        OK(pf_world_material_count(w, &count));
        CHECK(count == 2);
        OK(pf_world_fluid_material(w, &material));
        CHECK(material == 0);
        OK(pf_world_get_material_rest_density(w, 1, &rho0));
        CHECK(rho0 == 1500.0);
        /* A larger buffer than needed is fine; the tail stays untouched. */
        OK(pf_world_get_materials(w, mats, sizeof mats / sizeof *mats, &needed));
        CHECK(needed == 27 && mats[0] == 0 && mats[26] == 0 && mats[27] == 0xabcd);

        /* A world holds at most 256 materials; the one too many adds nothing. */
        PfWorld *full = NULL;
        OK(pf_world_create(&params, &full));
        for (int i = 1; i < 256; i++) {
            OK(pf_world_add_material(full, 100.0 + i, &id));
            CHECK(id == i);
        }
        REJECT(full, PF_ERROR_INVALID_ARGUMENT, pf_world_add_material(full, 1000.0, &id));
        CHECK(strstr(last_msg, "at most 256 materials") != NULL);
        CHECK(id == 255);
        OK(pf_world_material_count(full, &count));
        CHECK(count == 256);
        OK(pf_world_set_fluid_material(full, 255));
        OK(pf_world_get_material_rest_density(full, 255, &rho0));
        CHECK(rho0 == 355.0);
        REJECT(full, PF_ERROR_INVALID_ARGUMENT, pf_world_set_fluid_material(full, 256));
        OK(pf_world_fluid_material(full, &material));
        CHECK(material == 255);
        pf_world_destroy(full);
    }

    /* Functions returning nothing leave the last message alone, even given NULL. */
    EXPECT(PF_ERROR_NULL_POINTER, pf_world_time(w, NULL));
    char kept[512];
    snprintf(kept, sizeof kept, "%s", pf_last_error_message());
    pf_world_destroy(NULL);
    CHECK(strcmp(pf_last_error_message(), kept) == 0);
    rejected++;

    /* Calls after all those failures work normally and clear the message. */
    size_t nb = 0, nb_mesh = 0;
    OK(pf_world_boundary_count(w, &nb));
    OK(pf_world_add_mesh(w, mesh_v, 4, mesh_i, 4));
    OK(pf_world_boundary_count(w, &nb_mesh));
    CHECK(nb_mesh > nb + 10);
    OK(pf_world_add_fluid_particles(w, xyz, 2));
    OK(pf_world_fluid_count(w, &n));
    CHECK(n == 29);
    OK(pf_world_step(w, 0.0));
    OK(pf_world_last_step_stats(w, &st));
    CHECK(st.step_count == 2 && st.nan_count == 0);

    pf_world_destroy(w);
    printf("misuse: ok, %d rejected calls checked\n", rejected);
    return 0;
}
