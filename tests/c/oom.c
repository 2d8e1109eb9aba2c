/* Allocation failure is a status, not an abort: in a child process whose address space is
 * limited (setrlimit(RLIMIT_AS)) to a little above what it already uses, adding a huge fluid
 * box, a huge container or a huge mesh, and stepping or advancing a world that grew since its
 * last step, must each return PF_ERROR_OUT_OF_MEMORY and leave the world exactly as it was;
 * with the limit lifted the same world must step on normally. So must stepping a world with
 * a crowd of particles on top of each other, whose neighbour lists outgrow the room reserved
 * before the step and run out of memory during it.
 *
 * The limit is set relative to the child's current usage (read from /proc/self/statm), so
 * that the test does not depend on how much the process maps at start. Valgrind replaces
 * the allocator and the address-space layout, so this test does not run under it.
 * Usage: oom */
#define _POSIX_C_SOURCE 200809L

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

#if defined(__linux__)
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

/* The call must return PF_ERROR_OUT_OF_MEMORY, say so, and change nothing. */
#define OUT_OF_MEMORY(w, call)                                                           \
    do {                                                                                 \
        WorldSnapshot before_ = world_snapshot(w);                                       \
        EXPECT(PF_ERROR_OUT_OF_MEMORY, call);                                            \
        if (strstr(pf_last_error_message(), "out of memory") == NULL)                    \
            FAIL("%s: the message does not say out of memory", #call);                   \
        WorldSnapshot after_ = world_snapshot(w);                                        \
        if (!same_world(&before_, &after_)) FAIL("%s changed the world", #call);         \
    } while (0)

/* Bytes of address space the process uses now. */
static double address_space(void) {
    FILE *f = fopen("/proc/self/statm", "r");
    CHECK(f != NULL);
    unsigned long pages = 0;
    CHECK(fscanf(f, "%lu", &pages) == 1);
    fclose(f);
    return (double)pages * (double)sysconf(_SC_PAGESIZE);
}

/* Limits the address space to `headroom` bytes above the current usage (soft limit only,
 * so that it can be lifted again), or lifts the limit when `headroom` is negative. */
static void limit_address_space(double headroom) {
    struct rlimit limit;
    CHECK(getrlimit(RLIMIT_AS, &limit) == 0);
    limit.rlim_cur = headroom < 0 ? limit.rlim_max : (rlim_t)(address_space() + headroom);
    CHECK(setrlimit(RLIMIT_AS, &limit) == 0);
}

static int child(void) {
    PfParams params;
    OK(pf_params_default(&params));
    params.threads = 2;
    PfWorld *w = NULL;
    OK(pf_world_create(&params, &w));
    const float lo[3] = {0.0f, 0.0f, 0.0f}, hi[3] = {0.5f, 0.5f, 0.5f};
    OK(pf_world_add_container_box(w, lo, hi, 1));
    const float start[3] = {0.05f, 0.05f, 0.05f};
    const size_t small[3] = {6, 6, 6};
    OK(pf_world_add_fluid_box(w, start, small, NULL));
    /* One step before the limit, so that every thread has its allocator arena. */
    OK(pf_world_step(w, 0.0));

    limit_address_space(32e6);
    /* 6.4e7 particles, about 5 GB. */
    const size_t huge[3] = {400, 400, 400};
    OUT_OF_MEMORY(w, pf_world_add_fluid_box(w, start, huge, NULL));
    /* A 50 m box: 2.4e7 wall particles, about 600 MB. */
    const float far[3] = {50.0f, 50.0f, 50.0f};
    OUT_OF_MEMORY(w, pf_world_add_container_box(w, lo, far, 1));
    /* A 100 m triangle: about 1e7 samples, more than a gigabyte to sample it. */
    const float tri_v[9] = {0.0f, 0.0f, 0.0f, 100.0f, 0.0f, 0.0f, 0.0f, 0.0f, 100.0f};
    const uint32_t tri_i[3] = {0, 1, 2};
    OUT_OF_MEMORY(w, pf_world_add_mesh(w, tri_v, 3, tri_i, 1));

    /* 1e5 more particles fit (7 MB), but their first step needs tens of MB more. */
    limit_address_space(-1.0);
    const size_t more[3] = {50, 50, 40};
    const float aside[3] = {1.0f, 0.05f, 0.05f};
    /* Fluid outside every container would not be created: a second box holds this block. */
    const float lo2[3] = {0.9f, 0.0f, 0.0f}, hi2[3] = {3.6f, 2.6f, 2.1f};
    OK(pf_world_add_container_box(w, lo2, hi2, 1));
    OK(pf_world_add_fluid_box(w, aside, more, NULL));
    size_t made = 0;
    OK(pf_world_last_added_count(w, &made));
    CHECK(made == 50 * 50 * 40);
    limit_address_space(8e6);
    OUT_OF_MEMORY(w, pf_world_step(w, 0.0));
    OUT_OF_MEMORY(w, pf_world_advance(w, 0.01));
    OUT_OF_MEMORY(w, pf_world_relax(w, 0.01, 4.0));

    /* With the limit lifted the same world steps on, from where it was. */
    limit_address_space(-1.0);
    WorldSnapshot before = world_snapshot(w);
    OK(pf_world_step(w, 0.0));
    OK(pf_world_advance(w, 0.01));
    WorldSnapshot after = world_snapshot(w);
    CHECK(after.fluid == before.fluid && after.steps > before.steps + 1);
    CHECK(after.time > before.time + 0.01 - 1e-12);
    PfStepStats st;
    OK(pf_world_last_step_stats(w, &st));
    CHECK(st.nan_count == 0);

    /* A crowd of particles within 2 cm of each other, each the neighbour of every other: the
     * step reserves room for about 53 neighbours a particle before it starts, within the
     * limit, but the crowd's lists need 20000² entries (1.6 GB) and grow during the step,
     * past the limit. (With the limit lifted the crowd is not stepped: its lists and the
     * corrections its projections may keep would need gigabytes.) */
    enum { CROWD = 20000 };
    float *crowd = malloc(3 * CROWD * sizeof *crowd);
    CHECK(crowd != NULL);
    uint32_t seed = 12345u;
    for (size_t i = 0; i < 3 * (size_t)CROWD; i++) {
        seed = seed * 1664525u + 1013904223u;
        crowd[i] = 0.25f + 0.02f * (float)(seed >> 8) / 16777216.0f;
    }
    OK(pf_world_add_fluid_particles(w, crowd, CROWD));
    free(crowd);
    limit_address_space(256e6);
    OUT_OF_MEMORY(w, pf_world_step(w, 0.0));
    OUT_OF_MEMORY(w, pf_world_advance(w, 0.01));
    limit_address_space(-1.0);
    pf_world_destroy(w);
    return 0;
}

int main(void) {
    fflush(stdout);
    pid_t pid = fork();
    CHECK(pid >= 0);
    if (pid == 0) exit(child());
    int status = 0;
    CHECK(waitpid(pid, &status, 0) == pid);
    if (WIFSIGNALED(status)) FAIL("the child was killed by signal %d", WTERMSIG(status));
    CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    printf("oom: ok\n");
    return 0;
}
#else
int main(void) {
    printf("oom: skipped (needs Linux)\n");
    return 0;
}
#endif
