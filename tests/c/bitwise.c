/* A small simulation whose result tests/c_api.rs compares bit for bit with the same setup
 * run through the Rust API. Keep the two in step (see `rust_reference` in tests/c_api.rs).
 * Usage: bitwise OUT_FILE
 * Writes the final positions as raw native-endian floats to OUT_FILE and prints
 * "hash <sha256 of the double-precision positions>". */
#include <stdio.h>
#include <stdlib.h>

#include "check.h"

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s OUT_FILE\n", argv[0]);
        return 2;
    }
    PfParams params;
    OK(pf_params_default(&params));
    params.particle_radius = 0.02;
    params.displacement_tolerance = 2e-5;
    params.solver = PF_SOLVER_CHEBYSHEV;
    params.chebyshev_rho = 0.85;
    params.threads = 2;
    PfWorld *world = NULL;
    OK(pf_world_create(&params, &world));

    const float lo[3] = {-0.005f, -0.005f, -0.005f};
    const float hi[3] = {0.5f, 0.4f, 0.3f};
    OK(pf_world_add_container_box(world, lo, hi, 2));
    const float start[3] = {0.03f, 0.03f, 0.03f};
    const size_t count[3] = {6, 7, 5};
    const float velocity[3] = {0.25f, 0.0f, -0.125f};
    OK(pf_world_add_fluid_box(world, start, count, velocity));
    const float drops[9] = {0.4f, 0.3f, 0.15f, 0.41f, 0.25f, 0.1f, 0.2f, 0.35f, 0.2f};
    const float drop_v[9] = {-0.5f, 0.0f, 0.0f, 0.0f, -1.0f, 0.1f, 0.0f, 0.0f, 0.0f};
    OK(pf_world_add_fluid_particles_with_velocities(world, drops, drop_v, 3));
    const float post[6] = {0.25f, 0.01f, 0.15f, 0.25f, 0.03f, 0.15f};
    OK(pf_world_add_boundary_particles(world, post, 2));

    OK(pf_world_step(world, 0.002));
    OK(pf_world_step(world, 0.0));
    OK(pf_world_step(world, 0.0));
    OK(pf_world_advance(world, 0.01));

    size_t needed = 0;
    EXPECT(PF_ERROR_BUFFER_TOO_SMALL, pf_world_get_positions(world, NULL, 0, &needed));
    float *pos = malloc(needed * sizeof *pos);
    CHECK(pos != NULL);
    OK(pf_world_get_positions(world, pos, needed, NULL));
    FILE *f = fopen(argv[1], "wb");
    CHECK(f != NULL);
    CHECK(fwrite(pos, sizeof *pos, needed, f) == needed);
    CHECK(fclose(f) == 0);

    char hash[65];
    OK(pf_world_positions_hash(world, hash, sizeof hash, NULL));
    printf("hash %s\n", hash);
    free(pos);
    pf_world_destroy(world);
    return 0;
}
