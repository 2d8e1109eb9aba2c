/* Obstacles from OBJ files and transformed meshes through the C API: a good OBJ file adds
 * as many particles as the same mesh given as arrays; scaling grows the count with the area; bad files
 * (missing, malformed face, index out of range, degenerate triangle) and bad transforms are
 * rejected with PF_ERROR_INVALID_ARGUMENT, a message naming the file and line, and no
 * particle added.
 * Usage: obj DIR   (a writable scratch directory) */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

/* A box from (0.2, 0.1, 0.2) to (0.4, 0.2, 0.4) m as OBJ text: 8 vertices, 6 quads. */
static const char *box_obj =
    "# a box\n"
    "v 0.2 0.1 0.2\nv 0.4 0.1 0.2\nv 0.4 0.2 0.2\nv 0.2 0.2 0.2\n"
    "v 0.2 0.1 0.4\nv 0.4 0.1 0.4\nv 0.4 0.2 0.4\nv 0.2 0.2 0.4\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";

/* The same box as arrays (the quads split into fans as the OBJ reader does). */
static const float box_vertices[24] = {
    0.2f, 0.1f, 0.2f, 0.4f, 0.1f, 0.2f, 0.4f, 0.2f, 0.2f, 0.2f, 0.2f, 0.2f,
    0.2f, 0.1f, 0.4f, 0.4f, 0.1f, 0.4f, 0.4f, 0.2f, 0.4f, 0.2f, 0.2f, 0.4f,
};
static const uint32_t box_indices[36] = {
    0, 3, 2, 0, 2, 1, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
    3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5,
};

static char dir[4096];

static const char *write_file(const char *name, const char *text) {
    static char path[8192];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) FAIL("cannot write %s", path);
    fputs(text, f);
    fclose(f);
    return path;
}

static PfWorld *new_world(void) {
    PfParams params;
    OK(pf_params_default(&params));
    params.threads = 1;
    PfWorld *w = NULL;
    OK(pf_world_create(&params, &w));
    return w;
}

static size_t boundary_count(PfWorld *w) {
    size_t n = 0;
    OK(pf_world_boundary_count(w, &n));
    return n;
}

/* The call must fail with PF_ERROR_INVALID_ARGUMENT, its message must contain `part`, and
 * the world must still hold `before` boundary particles. */
static size_t before;
static void expect_rejected(PfWorld *w, PfStatus status, const char *part) {
    if (status != PF_ERROR_INVALID_ARGUMENT)
        FAIL("expected PF_ERROR_INVALID_ARGUMENT, got %s", pf_status_name((int)status));
    const char *msg = pf_last_error_message();
    if (strstr(msg, part) == NULL) FAIL("message \"%s\" lacks \"%s\"", msg, part);
    CHECK(boundary_count(w) == before);
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: obj DIR\n");
        return 2;
    }
    snprintf(dir, sizeof dir, "%s", argv[1]);

    /* The OBJ file and the arrays give the same particles. */
    PfWorld *a = new_world();
    PfWorld *b = new_world();
    OK(pf_world_add_obj(a, write_file("box.obj", box_obj), NULL));
    OK(pf_world_add_mesh(b, box_vertices, 8, box_indices, 12));
    size_t n = boundary_count(a);
    CHECK(n > 100 && n == boundary_count(b));
    before = n;

    /* A transform: translated, the box keeps (about) its sample count. */
    PfTransform t;
    OK(pf_transform_identity(&t));
    CHECK(t.scale[0] == 1.0 && t.rotate_deg[1] == 0.0 && t.translate[2] == 0.0);
    t.translate[0] = 1.0;
    t.translate[1] = 2.0;
    t.translate[2] = 3.0;
    PfWorld *c = new_world();
    OK(pf_world_add_mesh_transformed(c, box_vertices, 8, box_indices, 12, &t));
    double moved = (double)boundary_count(c) / (double)n;
    CHECK(moved > 0.95 && moved < 1.05);

    /* Scaled by 2 in every direction: four times the area, about four times the samples. */
    OK(pf_transform_identity(&t));
    t.scale[0] = t.scale[1] = t.scale[2] = 2.0;
    t.rotate_deg[1] = 30.0;
    PfWorld *d = new_world();
    OK(pf_world_add_obj(d, write_file("box.obj", box_obj), &t));
    double ratio = (double)boundary_count(d) / (double)n;
    CHECK(ratio > 3.4 && ratio < 4.6);

    /* Bad files name the file and the line; bad transforms name the field. */
    char missing[8192];
    snprintf(missing, sizeof missing, "%s/missing.obj", dir);
    expect_rejected(a, pf_world_add_obj(a, missing, NULL), "cannot read OBJ file");
    expect_rejected(a, pf_world_add_obj(a, missing, NULL), "missing.obj");
    char text[1024];
    snprintf(text, sizeof text, "%s", box_obj);
    *strstr(text, "f 1 2 6 5") = '\0';
    strcat(text, "f 1 2 x5\n");
    expect_rejected(a, pf_world_add_obj(a, write_file("malformed.obj", text), NULL),
                    "malformed.obj:12: malformed face");
    snprintf(text, sizeof text, "%s", box_obj);
    strstr(text, "f 1 5 8 4")[6] = '9';
    expect_rejected(a, pf_world_add_obj(a, write_file("range.obj", text), NULL),
                    "range.obj:14: face vertex index 9 is out of range");
    snprintf(text, sizeof text, "%sf 1 2 2\n", box_obj);
    expect_rejected(a, pf_world_add_obj(a, write_file("degenerate.obj", text), NULL),
                    "degenerate.obj:16: face `f 1 2 2` is degenerate");
    OK(pf_transform_identity(&t));
    t.scale[1] = -1.0;
    expect_rejected(a, pf_world_add_obj(a, write_file("box.obj", box_obj), &t),
                    "transform.scale must be positive");
    OK(pf_transform_identity(&t));
    t.rotate_deg[2] = NAN;
    expect_rejected(a, pf_world_add_mesh_transformed(a, box_vertices, 8, box_indices, 12, &t),
                    "transform.rotate_deg must be finite");
    EXPECT(PF_ERROR_NULL_POINTER, pf_world_add_obj(a, NULL, NULL));
    EXPECT(PF_ERROR_NULL_POINTER, pf_world_add_obj(NULL, missing, NULL));
    EXPECT(PF_ERROR_NULL_POINTER, pf_transform_identity(NULL));
    CHECK(boundary_count(a) == n);

    pf_world_destroy(a);
    pf_world_destroy(b);
    pf_world_destroy(c);
    pf_world_destroy(d);
    printf("obj: ok (%zu samples on the box)\n", n);
    return 0;
}
