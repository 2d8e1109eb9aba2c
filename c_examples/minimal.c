/* The smallest useful embedding of projfluid: a block of water falls into a box. */
#include <stdio.h>

#include "projfluid.h"

int main(void) {
    PfParams params;
    PfWorld *world = NULL;
    pf_params_default(&params);
    if (pf_world_create(&params, &world) != PF_OK) {
        fprintf(stderr, "create: %s\n", pf_last_error_message());
        return 1;
    }
    const float lo[3] = {0.0f, 0.0f, 0.0f}, hi[3] = {0.5f, 0.5f, 0.5f};
    const float start[3] = {0.05f, 0.05f, 0.05f};
    const size_t count[3] = {6, 6, 6};
    if (pf_world_add_container_box(world, lo, hi, 1) != PF_OK ||
        pf_world_add_fluid_box(world, start, count, NULL) != PF_OK ||
        pf_world_advance(world, 0.1) != PF_OK) {
        fprintf(stderr, "error: %s\n", pf_last_error_message());
        pf_world_destroy(world);
        return 1;
    }
    float xyz[3 * 6 * 6 * 6];
    pf_world_get_positions(world, xyz, sizeof xyz / sizeof xyz[0], NULL);
    printf("projfluid %s: first particle at (%.3f, %.3f, %.3f) m\n", pf_version_string(), xyz[0],
           xyz[1], xyz[2]);
    pf_world_destroy(world);
    return 0;
}
