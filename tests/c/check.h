/* Small assertion helpers shared by the C tests of the projfluid C API. */
#ifndef PROJFLUID_TEST_CHECK_H
#define PROJFLUID_TEST_CHECK_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "projfluid.h"

/* Fails the test with the location and the library's last message. */
#define FAIL(...)                                                                        \
    do {                                                                                 \
        fprintf(stderr, "%s:%d: ", __FILE__, __LINE__);                                  \
        fprintf(stderr, __VA_ARGS__);                                                    \
        fprintf(stderr, " (last error: \"%s\")\n", pf_last_error_message());             \
        exit(1);                                                                         \
    } while (0)

#define CHECK(cond)                                                                      \
    do {                                                                                 \
        if (!(cond)) FAIL("check failed: %s", #cond);                                    \
    } while (0)

/* The call must return PF_OK and leave an empty message. */
#define OK(call)                                                                         \
    do {                                                                                 \
        PfStatus ok_status_ = (call);                                                    \
        if (ok_status_ != PF_OK)                                                         \
            FAIL("%s returned %s", #call, pf_status_name((int)ok_status_));              \
        if (pf_last_error_message()[0] != '\0')                                          \
            FAIL("%s succeeded but left a message", #call);                              \
    } while (0)

/* The call must return `expected` and leave a message that names the function. */
#define EXPECT(expected, call)                                                           \
    do {                                                                                 \
        PfStatus got_status_ = (call);                                                   \
        if (got_status_ != (expected))                                                   \
            FAIL("%s returned %s, expected %s", #call, pf_status_name((int)got_status_), \
                 pf_status_name((int)(expected)));                                       \
        const char *msg_ = pf_last_error_message();                                      \
        if (msg_ == NULL || strncmp(msg_, "pf_", 3) != 0 || strlen(msg_) < 12)           \
            FAIL("%s gave no helpful message", #call);                                   \
    } while (0)

/* What a rejected call must leave as it was: counts, time, steps and the positions' digest. */
typedef struct {
    size_t fluid, boundary;
    double time;
    uint64_t steps;
    char hash[65];
} WorldSnapshot;

static inline WorldSnapshot world_snapshot(const PfWorld *w) {
    WorldSnapshot s;
    PfStepStats st;
    OK(pf_world_fluid_count(w, &s.fluid));
    OK(pf_world_boundary_count(w, &s.boundary));
    OK(pf_world_time(w, &s.time));
    OK(pf_world_last_step_stats(w, &st));
    s.steps = st.step_count;
    OK(pf_world_positions_hash(w, s.hash, sizeof s.hash, NULL));
    return s;
}

static inline int same_world(const WorldSnapshot *a, const WorldSnapshot *b) {
    return a->fluid == b->fluid && a->boundary == b->boundary && a->time == b->time &&
           a->steps == b->steps && strcmp(a->hash, b->hash) == 0;
}

#endif
