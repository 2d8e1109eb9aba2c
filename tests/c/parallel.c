/* Two distinct worlds stepped in parallel from two threads give the same result as one
 * world stepped alone; one world used from two threads at once reports PF_ERROR_BUSY.
 * Usage: parallel [steps]   (default 6) */
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

static int steps = 6;

static PfWorld *make_world(void) {
    PfParams params;
    OK(pf_params_default(&params));
    params.threads = 1;
    PfWorld *w = NULL;
    OK(pf_world_create(&params, &w));
    const float lo[3] = {0.0f, 0.0f, 0.0f}, hi[3] = {0.35f, 0.35f, 0.25f};
    OK(pf_world_add_container_box(w, lo, hi, 1));
    const float start[3] = {0.05f, 0.05f, 0.05f};
    const size_t count[3] = {5, 5, 3};
    OK(pf_world_add_fluid_box(w, start, count, NULL));
    return w;
}

typedef struct {
    char hash[65];
    int failed;
} Result;

static void *run(void *arg) {
    Result *r = arg;
    PfWorld *w = make_world();
    for (int i = 0; i < steps; i++) {
        if (pf_world_step(w, 0.0) != PF_OK) {
            fprintf(stderr, "step failed: %s\n", pf_last_error_message());
            r->failed = 1;
            break;
        }
    }
    if (pf_world_positions_hash(w, r->hash, sizeof r->hash, NULL) != PF_OK) r->failed = 1;
    pf_world_destroy(w);
    return NULL;
}

static atomic_int advance_done, polling_started, advance_turned_away;

/* Advances the world once the main thread polls it, retrying while the poller holds it. */
static void *advance(void *arg) {
    PfWorld *w = arg;
    while (!atomic_load(&polling_started)) sched_yield();
    PfStatus s;
    while ((s = pf_world_advance(w, 0.05)) == PF_ERROR_BUSY)
        atomic_fetch_add(&advance_turned_away, 1);
    if (s != PF_OK) {
        fprintf(stderr, "advance failed: %s\n", pf_last_error_message());
        exit(1);
    }
    atomic_store(&advance_done, 1);
    return NULL;
}

/* Polls `w` from this thread while another thread advances it; returns the busy replies. */
static int poll_while_advancing(PfWorld *w, int *polls) {
    atomic_store(&advance_done, 0);
    atomic_store(&polling_started, 0);
    pthread_t tc;
    CHECK(pthread_create(&tc, NULL, advance, w) == 0);
    int busy = 0;
    while (!atomic_load(&advance_done)) {
        size_t n = 0;
        PfStatus s = pf_world_fluid_count(w, &n);
        atomic_store(&polling_started, 1);
        (*polls)++;
        if (s == PF_ERROR_BUSY) {
            busy++;
            CHECK(strstr(pf_last_error_message(), "another thread") != NULL);
        } else {
            CHECK(s == PF_OK && n == 75);
        }
        /* Lets the advancing thread run where threads share one core (or valgrind's lock). */
        sched_yield();
    }
    CHECK(pthread_join(tc, NULL) == 0);
    return busy;
}

int main(int argc, char **argv) {
    if (argc > 1) steps = atoi(argv[1]);

    Result alone = {{0}, 0}, a = {{0}, 0}, b = {{0}, 0};
    run(&alone);
    CHECK(!alone.failed);
    pthread_t ta, tb;
    CHECK(pthread_create(&ta, NULL, run, &a) == 0);
    CHECK(pthread_create(&tb, NULL, run, &b) == 0);
    CHECK(pthread_join(ta, NULL) == 0);
    CHECK(pthread_join(tb, NULL) == 0);
    CHECK(!a.failed && !b.failed);
    CHECK(strcmp(a.hash, alone.hash) == 0);
    CHECK(strcmp(b.hash, alone.hash) == 0);

    /* One world from two threads: the second caller is turned away, nothing breaks. A few
     * rounds, in case the scheduler never lets the two calls overlap in one of them. */
    PfWorld *w = make_world();
    int busy = 0, polls = 0, rounds = 0;
    while (busy == 0 && rounds < 5) {
        busy += poll_while_advancing(w, &polls);
        rounds++;
    }
    double t = 0.0;
    OK(pf_world_time(w, &t));
    CHECK(t > 0.05 * rounds - 1e-6 && t < 0.05 * rounds + 1e-6);
    pf_world_destroy(w);

    printf("parallel: ok, hash %.16s..., %d of %d polls found the world busy, advance turned "
           "away %d times\n",
           alone.hash, busy, polls, atomic_load(&advance_turned_away));
    if (busy == 0) FAIL("the concurrent use was never detected");
    return 0;
}
