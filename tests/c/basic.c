/* Builds a small world through the C API, steps it, and reads every output buffer.
 * Usage: basic [steps]   (default 5; the valgrind run uses fewer) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

/* A block of water in a box whose walls are fields: no boundary particle, and after a
 * settling fall the water stands in the box at about rest density, nothing escaped. */
static void field_walls(const PfParams *params, int steps) {
    PfWorld *world = NULL;
    OK(pf_world_create(params, &world));
    const float lo[3] = {-0.00625f, -0.00625f, -0.00625f};
    const float hi[3] = {0.30625f, 0.40625f, 0.30625f};
    OK(pf_world_add_container_field(world, lo, hi));
    const float start[3] = {0.05f, 0.1f, 0.05f};
    const size_t count[3] = {5, 4, 5};
    OK(pf_world_add_fluid_box(world, start, count, NULL));
    size_t n = 0, nb = 1;
    OK(pf_world_fluid_count(world, &n));
    OK(pf_world_boundary_count(world, &nb));
    CHECK(n == 100 && nb == 0);
    /* The water falls 5 cm onto the floor (0.1 s) and, outside valgrind, settles. */
    OK(pf_world_advance(world, steps > 2 ? 0.4 : 0.15));
    PfStepStats stats;
    OK(pf_world_last_step_stats(world, &stats));
    CHECK(stats.escaped_count == 0 && stats.nan_count == 0);
    float pos[300], rho[100];
    OK(pf_world_get_positions(world, pos, 300, NULL));
    OK(pf_world_get_densities(world, rho, 100, NULL));
    for (size_t i = 0; i < n; i++) {
        /* Inside the box, and not sunk into the floor: the floor holds the water up. */
        for (int a = 0; a < 3; a++) CHECK(pos[3 * i + a] > lo[a] && pos[3 * i + a] < hi[a]);
        CHECK(pos[3 * i + 1] > 0.01f);
        CHECK(rho[i] < 1030.0f);
    }
    pf_world_destroy(world);
}

/* Two liquids: water and a heavier material (1500 kg/m^3). Fluid added after choosing a
 * material is made of it, the materials read back in the order of every per-particle read
 * (the ids), and each particle's density reads in its own material's terms: a heavy layer
 * at rest under water reads about 1500 kg/m^3, the water over it about 1000. */
static void two_liquids(const PfParams *params, int steps) {
    PfWorld *world = NULL;
    OK(pf_world_create(params, &world));
    size_t materials = 0;
    uint16_t current = 7;
    OK(pf_world_material_count(world, &materials));
    OK(pf_world_fluid_material(world, &current));
    CHECK(materials == 1 && current == 0);
    double rho0 = 0.0;
    OK(pf_world_get_material_rest_density(world, 0, &rho0));
    CHECK(rho0 == params->rest_density);

    /* A second material of water's own density, and the heavy one. */
    uint16_t water = 0, heavy = 0;
    OK(pf_world_add_material(world, params->rest_density, &water));
    OK(pf_world_add_material(world, 1500.0, &heavy));
    CHECK(water == 1 && heavy == 2);
    OK(pf_world_material_count(world, &materials));
    CHECK(materials == 3);
    OK(pf_world_get_material_rest_density(world, heavy, &rho0));
    CHECK(rho0 == 1500.0);
    OK(pf_world_get_material_rest_density(world, water, &rho0));
    CHECK(rho0 == params->rest_density);
    OK(pf_world_fluid_material(world, &current));
    CHECK(current == 0); /* adding a material does not choose it */
    /* Materials start without physical viscosity; one is set and read back. */
    double nu = -1.0;
    OK(pf_world_get_material_kinematic_viscosity(world, heavy, &nu));
    CHECK(nu == 0.0);
    OK(pf_world_set_material_kinematic_viscosity(world, heavy, 1e-3));
    OK(pf_world_get_material_kinematic_viscosity(world, heavy, &nu));
    CHECK(nu == 1e-3);
    /* Materials start without surface tension; one is set, read back and taken off. */
    double sigma = -1.0;
    OK(pf_world_get_material_surface_tension(world, heavy, &sigma));
    CHECK(sigma == 0.0);
    OK(pf_world_set_material_surface_tension(world, heavy, 0.05));
    OK(pf_world_get_material_surface_tension(world, heavy, &sigma));
    CHECK(sigma == 0.05);
    OK(pf_world_set_material_surface_tension(world, heavy, 0.0));
    OK(pf_world_get_material_surface_tension(world, 0, &sigma));
    CHECK(sigma == params->surface_tension);

    /* A 6 x 5 x 6 lattice one spacing and r/4 from the walls: its two bottom layers heavy,
     * the three above them water (material 0), added as particles (not settled, so the
     * layers start on the lattice). */
    const float d = 0.05f, gap = 0.05625f, side = 5 * d + 2 * gap;
    const float lo[3] = {0.0f, 0.0f, 0.0f}, hi[3] = {side, 0.5f, side};
    OK(pf_world_add_container_box(world, lo, hi, 1));
    float layer_heavy[3 * 72], layer_water[3 * 108];
    size_t nh = 0, nw = 0;
    for (int k = 0; k < 6; k++)
        for (int j = 0; j < 5; j++)
            for (int i = 0; i < 6; i++) {
                float *p = j < 2 ? &layer_heavy[3 * nh++] : &layer_water[3 * nw++];
                p[0] = gap + (float)i * d;
                p[1] = gap + (float)j * d;
                p[2] = gap + (float)k * d;
            }
    CHECK(nh == 72 && nw == 108);
    OK(pf_world_set_fluid_material(world, heavy));
    OK(pf_world_fluid_material(world, &current));
    CHECK(current == heavy);
    OK(pf_world_add_fluid_particles(world, layer_heavy, nh));
    OK(pf_world_set_fluid_material(world, 0));
    OK(pf_world_add_fluid_particles(world, layer_water, nw));
    /* A small box of the second water material in the air, far above the water. */
    OK(pf_world_set_fluid_material(world, water));
    const float box_start[3] = {0.15f, 0.4f, 0.15f};
    const size_t box_count[3] = {2, 2, 2};
    OK(pf_world_add_fluid_box(world, box_start, box_count, NULL));
    OK(pf_world_fluid_material(world, &current));
    CHECK(current == water);

    size_t n = 0, needed = 0;
    OK(pf_world_fluid_count(world, &n));
    CHECK(n == 72 + 108 + 8);
    uint16_t *mat = malloc(n * sizeof *mat);
    float *rho = malloc(n * sizeof *rho);
    float *pos = malloc(3 * n * sizeof *pos);
    CHECK(mat && rho && pos);
    EXPECT(PF_ERROR_BUFFER_TOO_SMALL, pf_world_get_materials(world, NULL, 0, &needed));
    CHECK(needed == n);
    OK(pf_world_get_materials(world, mat, n, &needed));
    CHECK(needed == n);
    size_t per_material[3] = {0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        CHECK(mat[i] < 3);
        per_material[mat[i]]++;
        /* In the order the particles were added. */
        CHECK(mat[i] == (i < 72 ? heavy : i < 180 ? 0 : water));
    }
    CHECK(per_material[0] == 108 && per_material[water] == 8 && per_material[heavy] == 72);

    /* A few steps (which reorder the particles' storage): the materials stay with their
     * particles and read in the same order. */
    for (int i = 0; i < (steps > 1 ? steps : 1); i++) OK(pf_world_step(world, 0.0));
    memset(mat, 0xff, n * sizeof *mat);
    OK(pf_world_get_materials(world, mat, n, NULL));
    for (size_t i = 0; i < n; i++) CHECK(mat[i] == (i < 72 ? heavy : i < 180 ? 0 : water));
    OK(pf_world_get_densities(world, rho, n, NULL));
    OK(pf_world_get_positions(world, pos, 3 * n, NULL));
    /* The heavy layer at rest: its densest particle near 1500 kg/m^3, its mean about 1.5
     * times the water's; the water's densest particle near 1000. Nothing moved far. */
    double heavy_mean = 0.0, water_mean = 0.0;
    float heavy_max = 0.0f, water_max = 0.0f;
    for (size_t i = 0; i < n; i++) {
        for (int a = 0; a < 3; a++) CHECK(isfinite(pos[3 * i + a]));
        CHECK(isfinite(rho[i]) && rho[i] > 0.0f);
        if (mat[i] == heavy) {
            CHECK(pos[3 * i + 1] < 0.11f); /* still in the bottom two layers */
            heavy_mean += rho[i] / 72.0;
            heavy_max = rho[i] > heavy_max ? rho[i] : heavy_max;
        } else if (mat[i] == 0) {
            water_mean += rho[i] / 108.0;
            water_max = rho[i] > water_max ? rho[i] : water_max;
        }
    }
    if (!(heavy_max > 1450.0f && heavy_max < 1560.0f && water_max > 950.0f &&
          water_max < 1040.0f && heavy_mean > 1.4 * water_mean && heavy_mean < 1.7 * water_mean))
        FAIL("heavy: densest %.1f, mean %.1f kg/m^3; water: densest %.1f, mean %.1f kg/m^3",
             heavy_max, heavy_mean, water_max, water_mean);
    free(mat);
    free(rho);
    free(pos);
    pf_world_destroy(world);
}

int main(int argc, char **argv) {
    int steps = argc > 1 ? atoi(argv[1]) : 5;

    /* Versions: the header and the library agree. */
    char version[64];
    snprintf(version, sizeof version, "%d.%d.%d", PF_VERSION_MAJOR, PF_VERSION_MINOR,
             PF_VERSION_PATCH);
    CHECK(strcmp(version, pf_version_string()) == 0);
    CHECK(pf_abi_version() == PF_ABI_VERSION);
    CHECK(strcmp(pf_status_name(PF_ERROR_BUFFER_TOO_SMALL), "PF_ERROR_BUFFER_TOO_SMALL") == 0);

    PfParams params;
    OK(pf_params_default(&params));
    CHECK(params.particle_radius == 0.025);
    CHECK(params.solver == PF_SOLVER_CHEBYSHEV);
    CHECK(params.gravity[1] == -9.81);
    CHECK(params.coarse_correction == 0);
    CHECK(params.kinematic_viscosity == 0.0 && params.no_slip == 1);
    CHECK(params.backend == PF_BACKEND_CPU);
    CHECK(params.vorticity_confinement == 0.0);
    params.threads = 2;
    OK(pf_params_validate(&params));

    /* The calm settings change the weighting, tau, Chebyshev's settings and the coarse
       correction only. */
    PfParams calm = params;
    OK(pf_params_calm(&calm));
    CHECK(calm.projection_weight == PF_WEIGHT_UNIFORM);
    CHECK(calm.displacement_tolerance == 3e-4 * params.particle_radius);
    CHECK(calm.chebyshev_rho == 0.99 && calm.chebyshev_gamma == 0.5);
    CHECK(calm.chebyshev_auto_rho == 0);
    CHECK(calm.coarse_correction == 0);
    CHECK(calm.kinematic_viscosity == params.kinematic_viscosity);
    CHECK(calm.no_slip == params.no_slip);
    CHECK(calm.backend == params.backend);
    CHECK(calm.threads == 2 && calm.solver == params.solver);
    CHECK(calm.stiffness == params.stiffness && calm.dt_max == params.dt_max);
    OK(pf_params_validate(&calm));

    PfWorld *world = NULL;
    OK(pf_world_create(&params, &world));
    CHECK(world != NULL);

    PfParams back;
    OK(pf_world_get_params(world, &back));
    CHECK(memcmp(&back.particle_radius, &params.particle_radius, sizeof(double)) == 0);
    CHECK(back.threads == 2 && back.max_outer_iterations == params.max_outer_iterations);
    CHECK(back.coarse_correction == 0);
    CHECK(back.backend == PF_BACKEND_CPU);

    /* The coarse correction turned on is kept by the world. */
    PfParams coarse_on = params;
    coarse_on.coarse_correction = 1;
    PfWorld *plain = NULL;
    OK(pf_world_create(&coarse_on, &plain));
    OK(pf_world_get_params(plain, &back));
    CHECK(back.coarse_correction == 1);
    pf_world_destroy(plain);

    /* The physical viscosity and free-slip walls are kept by the world, and the calm settings
       keep them. */
    PfParams honey = params;
    honey.kinematic_viscosity = 1e-2;
    honey.no_slip = 0;
    OK(pf_world_create(&honey, &plain));
    OK(pf_world_get_params(plain, &back));
    CHECK(back.kinematic_viscosity == 1e-2 && back.no_slip == 0);
    pf_world_destroy(plain);
    OK(pf_params_calm(&honey));
    CHECK(honey.kinematic_viscosity == 1e-2 && honey.no_slip == 0);

    /* Vorticity confinement, the last field, is kept by the world. */
    PfParams swirl = params;
    swirl.vorticity_confinement = 0.3;
    OK(pf_world_create(&swirl, &plain));
    OK(pf_world_get_params(plain, &back));
    CHECK(back.vorticity_confinement == 0.3);
    pf_world_destroy(plain);

    const float lo[3] = {-0.00625f, -0.00625f, -0.00625f};
    const float hi[3] = {0.40625f, 0.40625f, 0.30625f};
    OK(pf_world_add_container_box(world, lo, hi, 1));
    const float start[3] = {0.05f, 0.05f, 0.05f};
    const size_t count[3] = {5, 6, 4};
    OK(pf_world_add_fluid_box(world, start, count, NULL));
    const float extra[6] = {0.3f, 0.3f, 0.2f, 0.32f, 0.3f, 0.2f};
    const float extra_v[6] = {-1.0f, 0.0f, 0.0f, 0.0f, 0.5f, 0.0f};
    OK(pf_world_add_fluid_particles_with_velocities(world, extra, extra_v, 2));

    size_t n = 0, nb = 0;
    OK(pf_world_fluid_count(world, &n));
    OK(pf_world_boundary_count(world, &nb));
    CHECK(n == 5 * 6 * 4 + 2);
    CHECK(nb > 0);

    /* Before any step: zero statistics, zero densities, inputs read back exactly. */
    PfStepStats stats;
    OK(pf_world_last_step_stats(world, &stats));
    CHECK(stats.step_count == 0 && stats.dt == 0.0 && stats.escaped_count == 0);

    size_t needed = 0;
    /* The size query: NULL buffer with capacity 0. */
    EXPECT(PF_ERROR_BUFFER_TOO_SMALL, pf_world_get_positions(world, NULL, 0, &needed));
    CHECK(needed == 3 * n);
    float *pos = malloc(needed * sizeof *pos);
    float *vel = malloc(needed * sizeof *vel);
    float *rho = malloc(n * sizeof *rho);
    CHECK(pos && vel && rho);
    OK(pf_world_get_positions(world, pos, needed, &needed));
    CHECK(pos[0] == 0.05f && pos[1] == 0.05f && pos[2] == 0.05f);
    CHECK(fabsf(pos[3] - 0.1f) < 1e-6f); /* i runs fastest, spacing 2r = 0.05 */
    CHECK(pos[3 * (n - 2)] == 0.3f && pos[3 * (n - 1)] == 0.32f);
    OK(pf_world_get_velocities(world, vel, 3 * n, NULL));
    CHECK(vel[3 * (n - 2)] == -1.0f && vel[3 * (n - 1) + 1] == 0.5f && vel[0] == 0.0f);
    OK(pf_world_get_densities(world, rho, n, &needed));
    CHECK(needed == n && rho[0] > 0.0f); /* evaluated where the fluid was placed */

    /* Particle ids: 0..n-1 in the order the particles were added, the order of every read. */
    uint64_t *ids = malloc(n * sizeof *ids);
    CHECK(ids);
    EXPECT(PF_ERROR_BUFFER_TOO_SMALL, pf_world_get_ids(world, NULL, 0, &needed));
    CHECK(needed == n);
    EXPECT(PF_ERROR_BUFFER_TOO_SMALL, pf_world_get_ids(world, ids, n - 1, NULL));
    OK(pf_world_get_ids(world, ids, n, &needed));
    CHECK(needed == n);
    for (size_t i = 0; i < n; i++) CHECK(ids[i] == i);

    /* A fixed step, then CFL steps. */
    OK(pf_world_step(world, 0.002));
    for (int i = 1; i < steps; i++) OK(pf_world_step(world, 0.0));
    OK(pf_world_last_step_stats(world, &stats));
    CHECK(stats.step_count == (uint64_t)(steps > 1 ? steps : 1));
    CHECK(stats.dt > 0.0 && stats.outer_iterations >= 1 && stats.inner_iterations >= 1);
    CHECK(stats.density_error_avg_percent >= 0.0);
    CHECK(stats.density_error_max_percent >= stats.density_error_avg_percent);
    CHECK(stats.escaped_count == 0 && stats.nan_count == 0);
    double t = 0.0;
    OK(pf_world_time(world, &t));
    CHECK(t == stats.time && t > 0.0);

    OK(pf_world_advance(world, 0.004));
    double t2 = 0.0;
    OK(pf_world_time(world, &t2));
    CHECK(fabs(t2 - (t + 0.004)) < 1e-12);

    /* Relaxing at a damping rate so high that exp(-rate dt) underflows stops every
     * particle at the end of each step. */
    OK(pf_world_relax(world, 0.004, 1e6));
    OK(pf_world_time(world, &t2));
    CHECK(fabs(t2 - (t + 0.008)) < 1e-12);
    OK(pf_world_get_velocities(world, vel, 3 * n, NULL));
    for (size_t i = 0; i < 3 * n; i++) CHECK(vel[i] == 0.0f);
    OK(pf_world_advance(world, 0.004));
    OK(pf_world_time(world, &t2));

    OK(pf_world_get_positions(world, pos, 3 * n, NULL));
    OK(pf_world_get_velocities(world, vel, 3 * n, NULL));
    OK(pf_world_get_densities(world, rho, n, NULL));
    double mean_rho = 0.0;
    for (size_t i = 0; i < n; i++) {
        for (int a = 0; a < 3; a++) CHECK(isfinite(pos[3 * i + a]) && isfinite(vel[3 * i + a]));
        CHECK(pos[3 * i + 1] > -0.01f && pos[3 * i + 1] < 0.41f);
        CHECK(rho[i] > 0.0f);
        mean_rho += rho[i];
    }
    mean_rho /= (double)n;
    CHECK(mean_rho > 300.0 && mean_rho < 1500.0);
    /* Gravity pulled the two free particles down: together they lost at least half the
     * upward momentum free fall takes in t2 (the block itself stands at rest density). */
    CHECK(vel[3 * (n - 2) + 1] + vel[3 * (n - 1) + 1] < 0.5f - 9.81f * (float)t2);

    /* The steps sorted the particles; the ids still read back in order. */
    memset(ids, 0xff, n * sizeof *ids);
    OK(pf_world_get_ids(world, ids, n, NULL));
    for (size_t i = 0; i < n; i++) CHECK(ids[i] == i);

    char hash[65];
    OK(pf_world_positions_hash(world, hash, sizeof hash, &needed));
    CHECK(needed == 65 && strlen(hash) == 64);

    printf("basic: ok, %zu fluid, %zu boundary, t = %.4f s, mean density %.1f kg/m^3\n", n, nb,
           t2, mean_rho);
    free(pos);
    free(vel);
    free(rho);
    free(ids);
    pf_world_destroy(world);
    pf_world_destroy(NULL);
    field_walls(&params, steps);
    two_liquids(&params, steps);
    return 0;
}
