/* Worlds made from scenes through the C API (pf_world_create_from_scene).
 * Usage: scene [NAME_OR_PATH STEPS]
 * Without arguments: every misuse is rejected with its status and a message, leaving *out
 * NULL; the built-in fountain becomes a world with its fluid, walls, emitter and sink, which
 * steps. Prints "scene: ok N" with N the number of rejected calls checked.
 * With arguments: makes the world of NAME_OR_PATH (a built-in name or a JSON scene file),
 * takes STEPS CFL steps and prints "fluid N", "bodies N", "time T" and "hash H", which
 * tests/c_api.rs and the Python package's tests compare with their own runs of the scene. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

static int rejected = 0;

/* A rejected creation: expected status, a message naming `word`, and *out set to NULL. */
static void reject(PfStatus expected, const char *name, const char *word) {
    PfWorld *w = (PfWorld *)&rejected; /* must be overwritten with NULL */
    EXPECT(expected, pf_world_create_from_scene(name, &w));
    if (strstr(pf_last_error_message(), word) == NULL)
        FAIL("scene %s: the message does not name %s", name ? name : "NULL", word);
    CHECK(w == NULL);
    rejected++;
}

static int run(const char *name, unsigned long steps) {
    PfWorld *w = NULL;
    OK(pf_world_create_from_scene(name, &w));
    for (unsigned long i = 0; i < steps; i++) OK(pf_world_step(w, 0.0));
    size_t fluid = 0, bodies = 0;
    double time = 0.0;
    char hash[65];
    OK(pf_world_fluid_count(w, &fluid));
    OK(pf_world_body_count(w, &bodies));
    OK(pf_world_time(w, &time));
    OK(pf_world_positions_hash(w, hash, sizeof hash, NULL));
    printf("fluid %zu\nbodies %zu\ntime %.17g\nhash %s\n", fluid, bodies, time, hash);
    pf_world_destroy(w);
    return 0;
}

int main(int argc, char **argv) {
    if (argc == 3) return run(argv[1], strtoul(argv[2], NULL, 10));
    if (argc != 1) {
        fprintf(stderr, "usage: %s [NAME_OR_PATH STEPS]\n", argv[0]);
        return 2;
    }

    reject(PF_ERROR_NULL_POINTER, NULL, "name_or_path must not be NULL");
    EXPECT(PF_ERROR_NULL_POINTER, pf_world_create_from_scene("fountain", NULL));
    CHECK(strstr(pf_last_error_message(), "out must not be NULL") != NULL);
    rejected++;
    reject(PF_ERROR_INVALID_ARGUMENT, "no_such_scene", "dam_break_small");
    reject(PF_ERROR_INVALID_ARGUMENT, "no/such/scene.json", "does not exist");
    reject(PF_ERROR_INVALID_ARGUMENT, "\xff", "UTF-8");
    reject(PF_ERROR_INVALID_ARGUMENT, ".", "neither a built-in scene");

    /* The fountain: a 19 x 4 x 19 pool, a disc emitter and a drain. */
    PfWorld *w = NULL;
    OK(pf_world_create_from_scene("fountain", &w));
    CHECK(w != NULL);
    size_t fluid = 0, boundary = 0;
    OK(pf_world_fluid_count(w, &fluid));
    OK(pf_world_boundary_count(w, &boundary));
    CHECK(fluid == 19 * 4 * 19);
    CHECK(boundary > 0);
    PfParams params;
    OK(pf_world_get_params(w, &params));
    CHECK(params.particle_radius == 0.025);
    OK(pf_world_advance(w, 0.03));
    uint64_t emitted = 0;
    OK(pf_world_emitted_count(w, &emitted));
    CHECK(emitted > 0);
    pf_world_destroy(w);

    /* The drop: 16^3 particles without gravity or walls, with water's surface tension,
     * which pulls its corners in. */
    OK(pf_world_create_from_scene("droplet", &w));
    OK(pf_world_fluid_count(w, &fluid));
    OK(pf_world_boundary_count(w, &boundary));
    CHECK(fluid == 16 * 16 * 16 && boundary == 0);
    OK(pf_world_get_params(w, &params));
    CHECK(params.surface_tension == 0.0728 && params.gravity[1] == 0.0);
    double sigma = 0.0;
    OK(pf_world_get_material_surface_tension(w, 0, &sigma));
    CHECK(sigma == 0.0728);
    for (int i = 0; i < 5; i++) OK(pf_world_step(w, 0.0));
    pf_world_destroy(w);

    printf("scene: ok %d\n", rejected);
    return 0;
}
