/* Rigid bodies through the C API.
 * 1. A kinematic paddle driven by its velocity pushes water along a tank, with a dynamic
 *    sphere above the water and a static mesh body; prints the positions' hash and every
 *    body's state as exact bit patterns, which tests/c_api.rs compares with the same scene
 *    built through the Rust API (tests/support/c_bodies.rs). Keep the two in step.
 * 2. A dynamic sphere falls freely in air: its velocity is g·t.
 * 3. A kinematic body reaches a target pose in one step.
 * 4. Every kind of misuse is rejected with its status and message, changing no body.
 * Usage: bodies STEPS   (the steps of part 1) */
#include <inttypes.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

static void print_bits(const double *v, int n) {
    for (int i = 0; i < n; i++) {
        uint64_t bits;
        memcpy(&bits, &v[i], sizeof bits);
        printf(" %016" PRIx64, bits);
    }
}

/* Prints "body ID" and the pose, velocity, force and torque of every body as bits, then
 * "wall" and the walls' force. */
static void print_bodies(const PfWorld *w) {
    size_t n = 0;
    OK(pf_world_body_count(w, &n));
    for (size_t id = 0; id < n; id++) {
        PfPose pose;
        double lin[3], ang[3], force[3], torque[3];
        OK(pf_body_get_pose(w, id, &pose));
        OK(pf_body_get_velocity(w, id, lin, ang));
        OK(pf_body_get_force_torque(w, id, force, torque));
        printf("body %zu", id);
        print_bits(pose.position, 3);
        print_bits(pose.rotation, 4);
        print_bits(lin, 3);
        print_bits(ang, 3);
        print_bits(force, 3);
        print_bits(torque, 3);
        printf("\n");
    }
    double wall[3];
    OK(pf_world_get_wall_force(w, wall));
    printf("wall");
    print_bits(wall, 3);
    printf("\n");
}

static PfPose at(double x, double y, double z) {
    PfPose p;
    OK(pf_pose_identity(&p));
    p.position[0] = x;
    p.position[1] = y;
    p.position[2] = z;
    return p;
}

/* Part 1: the paddle tank. */
static void paddle(int steps) {
    PfParams params;
    OK(pf_params_default(&params));
    params.threads = 2;
    PfWorld *w = NULL;
    OK(pf_world_create(&params, &w));
    const float lo[3] = {0.0f, 0.0f, 0.0f}, hi[3] = {0.70625f, 0.5f, 0.30625f};
    OK(pf_world_add_container_box(w, lo, hi, 1));
    const float start[3] = {0.3f, 0.05f, 0.05f};
    const size_t count[3] = {8, 4, 5};
    OK(pf_world_add_fluid_box(w, start, count, NULL));

    /* A thin paddle across the tank, its face one spacing (0.05 m) from the water. */
    const double half[3] = {0.01, 0.22, 0.145};
    PfPose pose = at(0.24, 0.23, 0.153125);
    size_t id = 99;
    OK(pf_world_add_body_box(w, PF_BODY_KINEMATIC, half, 0.0, &pose, &id));
    CHECK(id == 0);
    const double push[3] = {0.5, 0.0, 0.0}, none[3] = {0.0, 0.0, 0.0};
    OK(pf_body_set_velocity(w, id, push, none));
    /* A wooden ball above the water, and a static tetrahedron by the far wall. */
    pose = at(0.5, 0.32, 0.15);
    OK(pf_world_add_body_sphere(w, PF_BODY_DYNAMIC, 0.04, 500.0, &pose, &id));
    CHECK(id == 1);
    const float tet_v[12] = {0.0f, 0.0f, 0.0f, 0.08f, 0.0f, 0.0f,
                             0.0f, 0.08f, 0.0f, 0.0f, 0.0f, 0.08f};
    const uint32_t tet_i[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    pose = at(0.58, 0.35, 0.1);
    OK(pf_world_add_body_mesh(w, PF_BODY_STATIC, tet_v, 4, tet_i, 4, 0.0, &pose, &id));
    CHECK(id == 2);

    for (int s = 0; s < steps; s++) OK(pf_world_step(w, 0.0));

    size_t n = 0;
    OK(pf_world_fluid_count(w, &n));
    float *pos = malloc(3 * n * sizeof *pos), *vel = malloc(3 * n * sizeof *vel);
    CHECK(pos != NULL && vel != NULL);
    OK(pf_world_get_positions(w, pos, 3 * n, NULL));
    OK(pf_world_get_velocities(w, vel, 3 * n, NULL));
    double centre[3];
    OK(pf_body_get_centre_of_mass(w, 0, centre));
    if (steps > 0) CHECK(centre[0] > 0.24);
    size_t behind = 0, pushed = 0;
    double momentum = 0.0;
    for (size_t i = 0; i < n; i++) {
        behind += (size_t)(pos[3 * i] < centre[0]);
        pushed += (size_t)(vel[3 * i] > 0.0f);
        momentum += vel[3 * i];
    }
    if (behind != 0) FAIL("%zu particles got behind the paddle", behind);
    if (steps > 0 && (pushed == 0 || momentum <= 0.0))
        FAIL("the paddle pushed nothing (momentum %g)", momentum);
    /* The water pushes back on the paddle once they touch. */
    double force[3], torque[3];
    OK(pf_body_get_force_torque(w, 0, force, torque));
    if (steps >= 10) CHECK(force[0] < 0.0);
    PfStepStats st;
    OK(pf_world_last_step_stats(w, &st));
    CHECK(st.escaped_count == 0 && st.nan_count == 0);

    char hash[65];
    OK(pf_world_positions_hash(w, hash, sizeof hash, NULL));
    printf("hash %s\n", hash);
    print_bodies(w);
    free(pos);
    free(vel);
    pf_world_destroy(w);
}

/* Parts 2 and 3, then part 4 on the same world. */
static PfWorld *free_fall(void) {
    PfParams params;
    OK(pf_params_default(&params));
    params.threads = 1;
    PfWorld *w = NULL;
    OK(pf_world_create(&params, &w));
    const float start[3] = {5.0f, 0.0f, 0.0f};
    const size_t count[3] = {2, 2, 2};
    OK(pf_world_add_fluid_box(w, start, count, NULL));
    PfPose pose = at(0.0, 2.0, 0.0);
    size_t ball = 9, crate = 9;
    OK(pf_world_add_body_sphere(w, PF_BODY_DYNAMIC, 0.1, 500.0, &pose, &ball));
    pose = at(-2.0, 0.0, 0.0);
    const double half[3] = {0.05, 0.05, 0.05};
    OK(pf_world_add_body_box(w, PF_BODY_KINEMATIC, half, 0.0, &pose, &crate));
    CHECK(ball == 0 && crate == 1);
    PfBodyKind kind = PF_BODY_STATIC;
    OK(pf_body_get_kind(w, ball, &kind));
    CHECK(kind == PF_BODY_DYNAMIC);

    for (int s = 0; s < 20; s++) OK(pf_world_step(w, 0.0));
    double t = 0.0, lin[3], ang[3], force[3], torque[3];
    OK(pf_world_time(w, &t));
    OK(pf_body_get_velocity(w, ball, lin, ang));
    const double gt = -9.81 * t;
    if (fabs(lin[1] - gt) > 1e-9 * fabs(gt)) FAIL("v_y = %.17g, g t = %.17g", lin[1], gt);
    CHECK(lin[0] == 0.0 && lin[2] == 0.0 && ang[0] == 0.0 && ang[1] == 0.0 && ang[2] == 0.0);
    OK(pf_body_get_force_torque(w, ball, force, torque));
    CHECK(force[0] == 0.0 && force[1] == 0.0 && force[2] == 0.0);
    OK(pf_body_get_pose(w, ball, &pose));
    CHECK(pose.position[1] < 2.0 && pose.rotation[0] == 1.0);

    /* The crate reaches a target pose, turned by 0.01 rad about z, in one step. */
    PfPose target = at(-1.998, 0.0, 0.0);
    target.rotation[0] = cos(0.005);
    target.rotation[3] = sin(0.005);
    OK(pf_body_set_target_pose(w, crate, &target));
    OK(pf_world_step(w, 0.0));
    PfStepStats st;
    OK(pf_world_last_step_stats(w, &st));
    OK(pf_body_get_pose(w, crate, &pose));
    for (int a = 0; a < 3; a++) CHECK(fabs(pose.position[a] - target.position[a]) < 1e-12);
    for (int a = 0; a < 4; a++) CHECK(fabs(pose.rotation[a] - target.rotation[a]) < 1e-12);
    OK(pf_body_get_velocity(w, crate, lin, ang));
    CHECK(fabs(lin[0] - 0.002 / st.dt) < 1e-9 && fabs(ang[2] - 0.01 / st.dt) < 1e-9);
    return w;
}

/* Everything that a rejected call must leave alone: counts and every body's state. */
typedef struct {
    size_t bodies, boundary;
    double state[8][19];
} Snapshot;

static Snapshot snapshot(const PfWorld *w) {
    Snapshot s;
    memset(&s, 0, sizeof s);
    OK(pf_world_body_count(w, &s.bodies));
    OK(pf_world_boundary_count(w, &s.boundary));
    CHECK(s.bodies <= 8);
    for (size_t id = 0; id < s.bodies; id++) {
        double *v = s.state[id];
        PfPose pose;
        OK(pf_body_get_pose(w, id, &pose));
        memcpy(v, pose.position, sizeof pose.position);
        memcpy(v + 3, pose.rotation, sizeof pose.rotation);
        OK(pf_body_get_velocity(w, id, v + 7, v + 10));
        OK(pf_body_get_force_torque(w, id, v + 13, v + 16));
    }
    return s;
}

static int rejected = 0;
static char last_msg[512];

/* A rejected call: expected status, a message naming `word`, and no change to any body. */
#define REJECT(w, expected, word, call)                                                   \
    do {                                                                                  \
        Snapshot before_ = snapshot(w);                                                   \
        EXPECT(expected, call);                                                           \
        snprintf(last_msg, sizeof last_msg, "%s", pf_last_error_message());               \
        if (strstr(last_msg, word) == NULL)                                               \
            FAIL("the message \"%s\" does not name %s", last_msg, word);                  \
        Snapshot after_ = snapshot(w);                                                    \
        if (memcmp(&before_, &after_, sizeof before_) != 0)                               \
            FAIL("%s changed the world", #call);                                          \
        rejected++;                                                                       \
    } while (0)

static void misuse(PfWorld *w) {
    const double half[3] = {0.05, 0.05, 0.05};
    PfPose pose = at(3.0, 0.0, 0.0), bad;
    size_t id = 12345, post = 0;
    OK(pf_world_add_body_cylinder(w, PF_BODY_STATIC, 0.05, 0.2, 0.0, &pose, &post));
    CHECK(post == 2);
    const int kin = PF_BODY_KINEMATIC, dyn = PF_BODY_DYNAMIC;
    const float tet_v[12] = {0, 0, 0, 0.1f, 0, 0, 0, 0.1f, 0, 0, 0, 0.1f};
    const uint32_t tet_i[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    const uint32_t open_i[3] = {0, 1, 2}, bad_i[3] = {0, 1, 4};
    const PfStatus NUL = PF_ERROR_NULL_POINTER, INV = PF_ERROR_INVALID_ARGUMENT;

    /* Adding: NULL pointers. */
    REJECT(w, NUL, "world", pf_world_add_body_box(NULL, kin, half, 0.0, &pose, &id));
    REJECT(w, NUL, "half_extents", pf_world_add_body_box(w, kin, NULL, 0.0, &pose, &id));
    REJECT(w, NUL, "pose", pf_world_add_body_box(w, kin, half, 0.0, NULL, &id));
    REJECT(w, NUL, "out_id", pf_world_add_body_box(w, kin, half, 0.0, &pose, NULL));
    REJECT(w, NUL, "pose", pf_world_add_body_sphere(w, kin, 0.1, 0.0, NULL, &id));
    REJECT(w, NUL, "out_id", pf_world_add_body_cylinder(w, kin, 0.1, 0.1, 0.0, &pose, NULL));
    REJECT(w, NUL, "vertices",
           pf_world_add_body_mesh(w, kin, NULL, 4, tet_i, 4, 0.0, &pose, &id));
    REJECT(w, NUL, "indices",
           pf_world_add_body_mesh(w, kin, tet_v, 4, NULL, 4, 0.0, &pose, &id));
    /* Kinds, densities, sizes. */
    REJECT(w, INV, "kind", pf_world_add_body_box(w, 3, half, 0.0, &pose, &id));
    REJECT(w, INV, "kind", pf_world_add_body_box(w, -1, half, 0.0, &pose, &id));
    REJECT(w, INV, "density", pf_world_add_body_box(w, dyn, half, 0.0, &pose, &id));
    REJECT(w, INV, "density", pf_world_add_body_box(w, dyn, half, -500.0, &pose, &id));
    REJECT(w, INV, "density", pf_world_add_body_box(w, kin, half, -1.0, &pose, &id));
    REJECT(w, INV, "density", pf_world_add_body_sphere(w, dyn, 0.1, NAN, &pose, &id));
    REJECT(w, INV, "density", pf_world_add_body_sphere(w, kin, 0.1, NAN, &pose, &id));
    REJECT(w, INV, "density", pf_world_add_body_sphere(w, dyn, 0.1, INFINITY, &pose, &id));
    const double flat[3] = {0.05, 0.0, 0.05}, negative[3] = {0.05, 0.05, -0.1};
    const double nan_half[3] = {NAN, 0.05, 0.05};
    REJECT(w, INV, "half_extents[1]", pf_world_add_body_box(w, kin, flat, 0.0, &pose, &id));
    REJECT(w, INV, "half_extents[2]", pf_world_add_body_box(w, kin, negative, 0.0, &pose, &id));
    REJECT(w, INV, "half_extents[0]", pf_world_add_body_box(w, kin, nan_half, 0.0, &pose, &id));
    REJECT(w, INV, "radius", pf_world_add_body_sphere(w, kin, 0.0, 0.0, &pose, &id));
    REJECT(w, INV, "radius", pf_world_add_body_sphere(w, dyn, NAN, 500.0, &pose, &id));
    REJECT(w, INV, "radius", pf_world_add_body_cylinder(w, kin, -0.1, 0.2, 0.0, &pose, &id));
    REJECT(w, INV, "height", pf_world_add_body_cylinder(w, kin, 0.1, 0.0, 0.0, &pose, &id));
    const double huge[3] = {1e4, 1e4, 1e4};
    REJECT(w, INV, "too large", pf_world_add_body_box(w, kin, huge, 0.0, &pose, &id));
    REJECT(w, INV, "closed",
           pf_world_add_body_mesh(w, dyn, tet_v, 4, open_i, 1, 500.0, &pose, &id));
    REJECT(w, INV, "triangles[0][2]",
           pf_world_add_body_mesh(w, kin, tet_v, 4, bad_i, 1, 0.0, &pose, &id));
    REJECT(w, INV, "vertex_count",
           pf_world_add_body_mesh(w, kin, tet_v, 0, tet_i, 4, 0.0, &pose, &id));
    /* Poses. */
    bad = pose;
    bad.position[1] = NAN;
    REJECT(w, INV, "pose.position", pf_world_add_body_box(w, kin, half, 0.0, &bad, &id));
    bad = pose;
    bad.rotation[1] = 0.01; /* |q| − 1 = 5e-5 */
    REJECT(w, INV, "pose.rotation", pf_world_add_body_box(w, kin, half, 0.0, &bad, &id));
    bad = pose;
    bad.rotation[0] = 0.0; /* |q| = 0 */
    REJECT(w, INV, "pose.rotation", pf_world_add_body_box(w, kin, half, 0.0, &bad, &id));
    bad = pose;
    bad.rotation[3] = INFINITY;
    REJECT(w, INV, "pose.rotation", pf_world_add_body_box(w, kin, half, 0.0, &bad, &id));
    CHECK(id == 12345);

    /* Moving: unknown ids, static bodies, bad poses and velocities. */
    const double v[3] = {1.0, 0.0, 0.0}, nan_v[3] = {0.0, NAN, 0.0};
    const double inf_v[3] = {0.0, 0.0, -INFINITY};
    PfPose ball_pose;
    OK(pf_body_get_pose(w, 0, &ball_pose));
    bad = ball_pose;
    bad.rotation[0] = 1.0 + 2e-6;
    REJECT(w, NUL, "world", pf_body_set_pose(NULL, 0, &ball_pose));
    REJECT(w, NUL, "pose", pf_body_set_pose(w, 0, NULL));
    REJECT(w, INV, "id 3", pf_body_set_pose(w, 3, &ball_pose));
    REJECT(w, INV, "id 18446744073709551615", pf_body_set_pose(w, SIZE_MAX, &ball_pose));
    REJECT(w, INV, "static", pf_body_set_pose(w, post, &ball_pose));
    REJECT(w, INV, "pose.rotation", pf_body_set_pose(w, 0, &bad));
    bad = ball_pose;
    bad.position[2] = -INFINITY;
    REJECT(w, INV, "pose.position", pf_body_set_pose(w, 0, &bad));
    REJECT(w, NUL, "world", pf_body_set_velocity(NULL, 0, v, v));
    REJECT(w, NUL, "linear", pf_body_set_velocity(w, 0, NULL, v));
    REJECT(w, NUL, "angular", pf_body_set_velocity(w, 0, v, NULL));
    REJECT(w, INV, "linear", pf_body_set_velocity(w, 0, nan_v, v));
    REJECT(w, INV, "angular", pf_body_set_velocity(w, 1, v, inf_v));
    REJECT(w, INV, "id 7", pf_body_set_velocity(w, 7, v, v));
    REJECT(w, INV, "static", pf_body_set_velocity(w, post, v, v));
    REJECT(w, NUL, "world", pf_body_set_target_pose(NULL, 1, &ball_pose));
    REJECT(w, NUL, "pose", pf_body_set_target_pose(w, 1, NULL));
    REJECT(w, INV, "dynamic", pf_body_set_target_pose(w, 0, &ball_pose));
    REJECT(w, INV, "static", pf_body_set_target_pose(w, post, &ball_pose));
    REJECT(w, INV, "id 3", pf_body_set_target_pose(w, 3, &ball_pose));
    bad = ball_pose;
    bad.rotation[2] = NAN;
    REJECT(w, INV, "pose.rotation", pf_body_set_target_pose(w, 1, &bad));

    /* Reading: unknown ids and NULL outputs, which leave the other outputs untouched. */
    double a[3] = {7.0, 7.0, 7.0}, b[3] = {7.0, 7.0, 7.0};
    size_t n = 77;
    PfBodyKind kind = PF_BODY_DYNAMIC;
    REJECT(w, NUL, "world", pf_world_body_count(NULL, &n));
    REJECT(w, NUL, "out", pf_world_body_count(w, NULL));
    REJECT(w, INV, "id 3", pf_body_get_pose(w, 3, &pose));
    REJECT(w, NUL, "out", pf_body_get_pose(w, 0, NULL));
    REJECT(w, INV, "id 3", pf_body_get_kind(w, 3, &kind));
    REJECT(w, NUL, "out", pf_body_get_kind(w, 0, NULL));
    REJECT(w, INV, "id 3", pf_body_get_velocity(w, 3, a, b));
    REJECT(w, NUL, "angular", pf_body_get_velocity(w, 0, a, NULL));
    REJECT(w, NUL, "linear", pf_body_get_velocity(w, 0, NULL, b));
    REJECT(w, INV, "id 3", pf_body_get_force_torque(w, 3, a, b));
    REJECT(w, NUL, "torque", pf_body_get_force_torque(w, 0, a, NULL));
    REJECT(w, NUL, "force", pf_body_get_force_torque(w, 0, NULL, b));
    REJECT(w, INV, "id 3", pf_body_get_centre_of_mass(w, 3, a));
    REJECT(w, NUL, "out", pf_body_get_centre_of_mass(w, 0, NULL));
    REJECT(w, NUL, "world", pf_world_get_wall_force(NULL, a));
    REJECT(w, NUL, "force", pf_world_get_wall_force(w, NULL));
    REJECT(w, NUL, "out", pf_pose_identity(NULL));
    CHECK(n == 77 && kind == PF_BODY_DYNAMIC);
    for (int i = 0; i < 3; i++) CHECK(a[i] == 7.0 && b[i] == 7.0);

    /* Valid calls still work: a quaternion within 1e-6 of unit length is accepted, and a
     * body added after the rejections gets the next id. */
    pose.rotation[0] = 1.0 + 5e-7;
    OK(pf_body_set_pose(w, 1, &pose));
    OK(pf_body_set_velocity(w, 1, v, v));
    OK(pf_world_add_body_box(w, PF_BODY_KINEMATIC, half, 0.0, &pose, &id));
    CHECK(id == 3);
    OK(pf_world_step(w, 0.0));
    OK(pf_world_body_count(w, &n));
    CHECK(n == 4);
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s STEPS\n", argv[0]);
        return 2;
    }
    paddle(atoi(argv[1]));
    PfWorld *w = free_fall();
    misuse(w);
    pf_world_destroy(w);
    printf("bodies: ok, %d rejected calls\n", rejected);
    return 0;
}
