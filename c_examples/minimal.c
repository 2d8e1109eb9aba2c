#include <stdio.h>
#include "projfluid.h"

int main(void) {
    PfParams params;
    PfWorld *world = NULL;
    pf_params_default(&params);                          /* r = 0.025 m, water, Chebyshev */
    if (pf_world_create(&params, &world) != PF_OK) return 1;
    const float lo[3] = {0, 0, 0}, hi[3] = {0.5f, 0.5f, 0.5f}, start[3] = {0.05f, 0.05f, 0.05f};
    const size_t count[3] = {6, 6, 6};
    size_t made = 0;                                     /* particles inside a solid are not made */
    PfStepStats last;
    if (pf_world_add_container_box(world, lo, hi, 1) != PF_OK ||
        pf_world_add_fluid_box(world, start, count, NULL) != PF_OK ||
        pf_world_last_added_count(world, &made) != PF_OK ||
        pf_world_advance(world, 0.1) != PF_OK ||        /* 0.1 s of CFL-limited steps */
        pf_world_last_step_stats(world, &last) != PF_OK) {
        fprintf(stderr, "%s\n", pf_last_error_message());
        pf_world_destroy(world);
        return 1;
    }
    float xyz[3 * 6 * 6 * 6];
    pf_world_get_positions(world, xyz, 3 * made, NULL);
    double height = 0;
    for (size_t i = 0; i < made; i++) height += xyz[3 * i + 1] / made;
    printf("%zu particles, mean height %.3f m (0.175 m at the start); "
           "last step: %zu outer iterations%s\n",
           made, height, last.outer_iterations,
           last.hit_max_iterations ? ", iteration limit reached" : "");
    pf_world_destroy(world);
    return 0;
}
