/* Two-way coupling through the projfluid C API: a rigid-body integrator written here, in C,
 * floats a box on water. The box is a kinematic body of the fluid world; after every step
 * the program reads the fluid's force and torque on it, advances the box's velocity under
 * gravity and that load, and sets the box's next pose and velocity back into the world, as
 * an engine's rigid solver would. With the argument "dynamic" the library integrates the
 * same box itself instead (a dynamic body), for comparison.
 *
 * The tank is 0.6 m x 0.6 m with water 0.3 m deep; the box, 0.2 x 0.12 x 0.2 m of density
 * 500 kg/m³, is dropped from just above the water. Prints the box's height every 0.25 s and
 * a final line with its height, submerged fraction and speed.
 *
 * Build (static):  cc -std=c11 -O2 -I include c_examples/coupling.c \
 *                      target/release/libprojfluid.a -lm -lpthread -ldl -o coupling
 * Usage: coupling [coupled|dynamic] [seconds]   (default coupled, 3 s) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "projfluid.h"

static const double GRAVITY = -9.81;   /* m/s², along y */
static const double DENSITY = 500.0;   /* kg/m³ */
static const double HALF[3] = {0.1, 0.06, 0.1}; /* m */

/* Prints the last error and exits when a call fails. */
static void check(PfStatus status, const char *what) {
    if (status != PF_OK) {
        fprintf(stderr, "coupling: %s failed with %s: %s\n", what, pf_status_name((int)status),
                pf_last_error_message());
        exit(1);
    }
}

/* The box's rigid state as this program integrates it. */
typedef struct {
    double mass;         /* kg */
    double inertia[3];   /* principal moments in the body frame, kg·m² */
    double centre[3];    /* centre of mass, m */
    double q[4];         /* orientation w, x, y, z */
    double v[3];         /* m/s */
    double w[3];         /* rad/s, world axes */
} Rigid;

/* The rotation matrix of unit quaternion q. */
static void matrix(const double q[4], double m[3][3]) {
    double w = q[0], x = q[1], y = q[2], z = q[3];
    m[0][0] = 1 - 2 * (y * y + z * z); m[0][1] = 2 * (x * y - w * z); m[0][2] = 2 * (x * z + w * y);
    m[1][0] = 2 * (x * y + w * z); m[1][1] = 1 - 2 * (x * x + z * z); m[1][2] = 2 * (y * z - w * x);
    m[2][0] = 2 * (x * z - w * y); m[2][1] = 2 * (y * z + w * x); m[2][2] = 1 - 2 * (x * x + y * y);
}

/* Symplectic Euler for the velocities: v += dt (g + F/M), ω += dt I_w⁻¹ (τ − ω × I_w ω) with
 * I_w = R I Rᵀ, solved in the body frame where I is diagonal. */
static void accelerate(Rigid *b, const double force[3], const double torque[3], double dt) {
    for (int a = 0; a < 3; a++) b->v[a] += dt * force[a] / b->mass;
    b->v[1] += dt * GRAVITY;
    double r[3][3];
    matrix(b->q, r);
    double wb[3], tb[3], lb[3], gyro[3];
    for (int a = 0; a < 3; a++) { /* to the body frame: Rᵀ */
        wb[a] = r[0][a] * b->w[0] + r[1][a] * b->w[1] + r[2][a] * b->w[2];
        tb[a] = r[0][a] * torque[0] + r[1][a] * torque[1] + r[2][a] * torque[2];
        lb[a] = b->inertia[a] * wb[a];
    }
    gyro[0] = wb[1] * lb[2] - wb[2] * lb[1];
    gyro[1] = wb[2] * lb[0] - wb[0] * lb[2];
    gyro[2] = wb[0] * lb[1] - wb[1] * lb[0];
    for (int a = 0; a < 3; a++) wb[a] += dt * (tb[a] - gyro[a]) / b->inertia[a];
    for (int a = 0; a < 3; a++) /* back to world axes: R */
        b->w[a] = r[a][0] * wb[0] + r[a][1] * wb[1] + r[a][2] * wb[2];
}

/* Moves the box on with its velocity over dt: the centre by v dt, the orientation by the
 * rotation of angle |ω| dt about ω, applied on the left. */
static void move(Rigid *b, double dt) {
    for (int a = 0; a < 3; a++) b->centre[a] += dt * b->v[a];
    double angle = sqrt(b->w[0] * b->w[0] + b->w[1] * b->w[1] + b->w[2] * b->w[2]) * dt;
    if (angle == 0.0) return;
    double s = sin(angle / 2) / (angle / dt), c = cos(angle / 2);
    double d[4] = {c, s * b->w[0], s * b->w[1], s * b->w[2]}, q[4];
    const double *p = b->q;
    q[0] = d[0] * p[0] - d[1] * p[1] - d[2] * p[2] - d[3] * p[3];
    q[1] = d[0] * p[1] + d[1] * p[0] + d[2] * p[3] - d[3] * p[2];
    q[2] = d[0] * p[2] - d[1] * p[3] + d[2] * p[0] + d[3] * p[1];
    q[3] = d[0] * p[3] + d[1] * p[2] - d[2] * p[1] + d[3] * p[0];
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int a = 0; a < 4; a++) b->q[a] = q[a] / n;
}

int main(int argc, char **argv) {
    int coupled = !(argc > 1 && strcmp(argv[1], "dynamic") == 0);
    double seconds = argc > 2 ? atof(argv[2]) : 3.0;
    PfParams params;
    check(pf_params_default(&params), "pf_params_default"); /* r = 0.025 m */
    params.mass_factor = 1.0;
    PfWorld *world = NULL;
    check(pf_world_create(&params, &world), "pf_world_create");

    /* The tank, walls r/4 outside the nominal 0.6 x 0.8 x 0.6 m box, water 0.3 m deep. */
    const float lo[3] = {-0.00625f, -0.00625f, -0.00625f};
    const float hi[3] = {0.60625f, 0.80625f, 0.60625f};
    check(pf_world_add_container_box(world, lo, hi, 1), "pf_world_add_container_box");
    const float start[3] = {0.05f, 0.05f, 0.05f};
    const size_t count[3] = {11, 6, 11};
    check(pf_world_add_fluid_box(world, start, count, NULL), "pf_world_add_fluid_box");

    /* The box, its bottom 2 cm above the water. Its density sets the centre of mass that
     * the torque is reported about; as a kinematic body the fluid does not move it. */
    Rigid box = {0};
    box.mass = DENSITY * 8.0 * HALF[0] * HALF[1] * HALF[2];
    box.inertia[0] = box.mass / 3.0 * (HALF[1] * HALF[1] + HALF[2] * HALF[2]);
    box.inertia[1] = box.mass / 3.0 * (HALF[0] * HALF[0] + HALF[2] * HALF[2]);
    box.inertia[2] = box.mass / 3.0 * (HALF[0] * HALF[0] + HALF[1] * HALF[1]);
    box.centre[0] = 0.3; box.centre[1] = 0.325 + 0.02 + HALF[1]; box.centre[2] = 0.3;
    box.q[0] = 1.0;
    PfPose pose;
    check(pf_pose_identity(&pose), "pf_pose_identity");
    for (int a = 0; a < 3; a++) pose.position[a] = box.centre[a];
    size_t id = 0;
    int kind = coupled ? PF_BODY_KINEMATIC : PF_BODY_DYNAMIC;
    check(pf_world_add_body_box(world, kind, HALF, DENSITY, &pose, &id), "pf_world_add_body_box");
    printf("coupling: %s box of %.2f kg on water, %.2f s (projfluid %s)\n",
           coupled ? "C-integrated kinematic" : "library-integrated dynamic", box.mass, seconds,
           pf_version_string());

    double t = 0.0, next_print = 0.25;
    PfStepStats stats;
    while (t < seconds - 1e-9) {
        check(pf_world_step(world, 0.0), "pf_world_step");
        check(pf_world_last_step_stats(world, &stats), "pf_world_last_step_stats");
        check(pf_world_time(world, &t), "pf_world_time");
        if (coupled) {
            /* The step moved the box by the velocity set before it, as move() does here;
             * the load it reports acted on the box at that pose. */
            double force[3], torque[3];
            check(pf_body_get_force_torque(world, id, force, torque), "pf_body_get_force_torque");
            move(&box, stats.dt);
            accelerate(&box, force, torque, stats.dt);
            PfPose next;
            for (int a = 0; a < 3; a++) next.position[a] = box.centre[a];
            memcpy(next.rotation, box.q, sizeof box.q);
            check(pf_body_set_pose(world, id, &next), "pf_body_set_pose");
            check(pf_body_set_velocity(world, id, box.v, box.w), "pf_body_set_velocity");
        } else {
            check(pf_body_get_centre_of_mass(world, id, box.centre), "pf_body_get_centre_of_mass");
            check(pf_body_get_velocity(world, id, box.v, box.w), "pf_body_get_velocity");
        }
        if (t >= next_print - 1e-9) {
            printf("t = %.2f s  box centre at %.4f m, moving %+.3f m/s\n", t, box.centre[1],
                   box.v[1]);
            next_print += 0.25;
        }
    }
    double speed = sqrt(box.v[0] * box.v[0] + box.v[1] * box.v[1] + box.v[2] * box.v[2]);
    printf("final: centre %.4f m, speed %.4f m/s, steps %llu, escaped %zu, nan %zu\n",
           box.centre[1], speed, (unsigned long long)stats.step_count, stats.escaped_count,
           stats.nan_count);
    pf_world_destroy(world);
    return stats.escaped_count == 0 && stats.nan_count == 0 ? 0 : 1;
}
