/*
 * The numeric kernels of robotspec.collision._meshcore: box trees of triangle meshes, the
 * separating-axis proofs that two meshes are apart (or crossing), and points on a mesh, on plain
 * C arrays.
 *
 * Why a file of its own: it includes no Python or numpy header, so it compiles with any C99
 * compiler for any platform (CI cross-compiles it for Windows with mingw-w64, warnings as
 * errors), whatever the Python glue (_meshcore.c) needs. The glue includes this file into its
 * own translation unit, so the compiler inlines these static functions exactly as before the
 * split: the answers and the speed do not depend on it.
 *
 * Poses are row-major 4x4 (numpy's layout).
 */
#ifndef ROBOTSPEC_MESHCORE_KERNELS_H
#define ROBOTSPEC_MESHCORE_KERNELS_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define LEAF_TRIANGLES 1

typedef struct {
    double c[3], h[3]; /* box centre (mesh frame) and half extents along its axes */
    double ax[9];      /* the box's axes as columns (row-major), in the mesh frame */
    double rad;        /* half diagonal: the radius of a ball around c that holds the box */
    int32_t left, right; /* children (nodes), or -1 for a leaf */
    int32_t first, count; /* a leaf's triangles: order[first .. first + count) */
} Node;

/* A triangle as the separating-axis test reads it: corners, edges and normal (21 doubles). */
#define FEAT 21

typedef struct {
    int32_t n_tri, n_node;
    double *v;      /* 9 doubles per triangle: its three corners, in triangle order */
    double *f;      /* FEAT doubles per triangle: corners, edges, normal */
    int32_t *order; /* triangle index per leaf slot */
    Node *nodes;    /* node 0 is the root */
} Tree;

/*
 * Per query: B's triangles (FEAT doubles) and nodes (axes and centre, 12 doubles) moved into A's
 * frame, each once, and the traversal's stack. A stamp tells which query an entry was moved for.
 */
typedef struct Scratch {
    double *tri, *node;
    int64_t *tri_stamp, *node_stamp;
    int64_t now;
    int32_t *pairs;
    size_t cap;
} Scratch;

typedef struct {
    ptrdiff_t n;
    Tree **trees; /* one per geometry; NULL where the geometry is not a mesh */
    int32_t most_tri;
    Scratch *one; /* apart_one's scratch: used only with the GIL held, so never shared */
    /* Scratches of finished calls, kept for the next (taken and given back by the glue with the
     * GIL held, used without it): a call that releases the GIL owns its scratch while it runs,
     * so threads never share one, and none pays for allocating and stamping it afresh. */
    Scratch **spare;
    ptrdiff_t n_spare, cap_spare;
} MeshSet;

/* ------------------------------------------------------------------------------ building */

/* Eigenvectors of a symmetric 3x3 matrix m (row-major, destroyed) as the columns of v, by cyclic
 * Jacobi rotations: the axes of a node's box follow its triangles (a rotated cylinder gets a box
 * along its axis), which is what keeps the boxes of nearly touching meshes apart. */
static void eigenvectors(double *m, double *v) {
    for (int i = 0; i < 9; i++) v[i] = (i % 4 == 0) ? 1.0 : 0.0;
    for (int sweep = 0; sweep < 32; sweep++) {
        double off = fabs(m[1]) + fabs(m[2]) + fabs(m[5]);
        if (off < 1e-30) break;
        for (int p = 0; p < 2; p++) {
            for (int q = p + 1; q < 3; q++) {
                double apq = m[3 * p + q];
                if (fabs(apq) < 1e-300) continue;
                double theta = (m[3 * q + q] - m[3 * p + p]) / (2.0 * apq);
                double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), sn = t * c;
                for (int k = 0; k < 3; k++) { /* m = J^T m J */
                    double mkp = m[3 * k + p], mkq = m[3 * k + q];
                    m[3 * k + p] = c * mkp - sn * mkq;
                    m[3 * k + q] = sn * mkp + c * mkq;
                }
                for (int k = 0; k < 3; k++) {
                    double mpk = m[3 * p + k], mqk = m[3 * q + k];
                    m[3 * p + k] = c * mpk - sn * mqk;
                    m[3 * q + k] = sn * mpk + c * mqk;
                }
                for (int k = 0; k < 3; k++) {
                    double vkp = v[3 * k + p], vkq = v[3 * k + q];
                    v[3 * k + p] = c * vkp - sn * vkq;
                    v[3 * k + q] = sn * vkp + c * vkq;
                }
            }
        }
    }
    /* v is a product of rotations, so orthonormal; its handedness does not matter to the
     * separating-axis test (only absolute projections enter it). */
}

/* The oriented box of a node's triangles: axes from the covariance of their corners, extents
 * from the corners' projections (so it holds every corner, hence every triangle). */
static void box_of(const Tree *t, int32_t first, int32_t count, Node *nd) {
    double mean[3] = {0, 0, 0}, cov[9] = {0};
    double n = 3.0 * count;
    for (int32_t s = first; s < first + count; s++) {
        const double *p = t->v + 9 * t->order[s];
        for (int k = 0; k < 9; k++) mean[k % 3] += p[k] / n;
    }
    for (int32_t s = first; s < first + count; s++) {
        const double *p = t->v + 9 * t->order[s];
        for (int k = 0; k < 3; k++) {
            double d[3] = {p[3 * k] - mean[0], p[3 * k + 1] - mean[1], p[3 * k + 2] - mean[2]};
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++) cov[3 * a + b] += d[a] * d[b];
        }
    }
    eigenvectors(cov, nd->ax);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t s = first; s < first + count; s++) {
        const double *p = t->v + 9 * t->order[s];
        for (int k = 0; k < 3; k++) {
            for (int a = 0; a < 3; a++) {
                double x = nd->ax[a] * p[3 * k] + nd->ax[3 + a] * p[3 * k + 1] +
                           nd->ax[6 + a] * p[3 * k + 2];
                if (x < lo[a]) lo[a] = x;
                if (x > hi[a]) hi[a] = x;
            }
        }
    }
    double mid[3];
    for (int a = 0; a < 3; a++) {
        mid[a] = (lo[a] + hi[a]) / 2.0;
        /* A hair of room: the corners were projected with rounding. */
        nd->h[a] = (hi[a] - lo[a]) / 2.0 + 1e-12 * (fabs(lo[a]) + fabs(hi[a]));
    }
    for (int a = 0; a < 3; a++) {
        nd->c[a] = nd->ax[3 * a] * mid[0] + nd->ax[3 * a + 1] * mid[1] + nd->ax[3 * a + 2] * mid[2];
    }
    nd->rad = sqrt(nd->h[0] * nd->h[0] + nd->h[1] * nd->h[1] + nd->h[2] * nd->h[2]);
}

/* Sort key for the split: triangle centroids along one axis (qsort has no context). */
typedef struct {
    double key;
    int32_t tri;
} Keyed;

static int by_key(const void *a, const void *b) {
    double x = ((const Keyed *)a)->key, y = ((const Keyed *)b)->key;
    if (x < y) return -1;
    if (x > y) return 1;
    return ((const Keyed *)a)->tri - ((const Keyed *)b)->tri; /* stable: same tree every run */
}

static int tree_build(Tree *t, Keyed *scratch) {
    /* Top down, with an explicit stack of (node, first, count): no recursion on any input. */
    int32_t cap = 64, top = 0;
    int32_t *stack = malloc(sizeof(int32_t) * 3 * (size_t)cap);
    if (stack == NULL) return -1;
    t->n_node = 1;
    stack[0] = 0;
    stack[1] = 0;
    stack[2] = t->n_tri;
    top = 1;
    while (top > 0) {
        top--;
        int32_t id = stack[3 * top], first = stack[3 * top + 1], count = stack[3 * top + 2];
        Node *nd = &t->nodes[id];
        box_of(t, first, count, nd);
        nd->left = nd->right = -1;
        nd->first = first;
        nd->count = count;
        if (count <= LEAF_TRIANGLES) continue;
        /* Split at the median centroid along the box's longest side. */
        int axis = 0;
        if (nd->h[1] > nd->h[axis]) axis = 1;
        if (nd->h[2] > nd->h[axis]) axis = 2;
        const double u[3] = {nd->ax[axis], nd->ax[3 + axis], nd->ax[6 + axis]};
        for (int32_t s = 0; s < count; s++) {
            int32_t tri = t->order[first + s];
            const double *p = t->v + 9 * tri;
            scratch[s].key = u[0] * (p[0] + p[3] + p[6]) + u[1] * (p[1] + p[4] + p[7]) +
                             u[2] * (p[2] + p[5] + p[8]);
            scratch[s].tri = tri;
        }
        qsort(scratch, (size_t)count, sizeof(Keyed), by_key);
        for (int32_t s = 0; s < count; s++) t->order[first + s] = scratch[s].tri;
        int32_t half = count / 2;
        nd->left = t->n_node;
        nd->right = t->n_node + 1;
        nd->count = 0;
        t->n_node += 2;
        if (top + 2 > cap) {
            cap *= 2;
            int32_t *s2 = realloc(stack, sizeof(int32_t) * 3 * (size_t)cap);
            if (s2 == NULL) {
                free(stack);
                return -1;
            }
            stack = s2;
        }
        int32_t left = nd->left, right = nd->right;
        stack[3 * top] = left;
        stack[3 * top + 1] = first;
        stack[3 * top + 2] = half;
        top++;
        stack[3 * top] = right;
        stack[3 * top + 1] = first + half;
        stack[3 * top + 2] = count - half;
        top++;
    }
    free(stack);
    return 0;
}

static inline void sub3(const double *a, const double *b, double *o) {
    o[0] = a[0] - b[0];
    o[1] = a[1] - b[1];
    o[2] = a[2] - b[2];
}

static inline void cross3(const double *a, const double *b, double *o) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static inline double dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Corners (9), edges (9) and normal (3) of the triangle with corners v. */
static void features(const double *v, double *f) {
    memcpy(f, v, 9 * sizeof(double));
    sub3(v + 3, v, f + 9);
    sub3(v + 6, v + 3, f + 12);
    sub3(v, v + 6, f + 15);
    cross3(f + 9, f + 12, f + 18);
}

static void tree_free(Tree *t) {
    if (t == NULL) return;
    free(t->v);
    free(t->f);
    free(t->order);
    free(t->nodes);
    free(t);
}

/*
 * Box a (half extents ha0, its own frame) and box b (half extents hb, centred at t with axes the
 * columns of r, in a's frame): 1 when one of the fifteen separating axes leaves more than eps
 * between them (a grown by eps on every side holds the ball of radius eps around it). The
 * absolute rotation entries get a little extra so rounding never turns an overlap into a gap.
 */
static int boxes_apart(const double *r, const double *t, const double *ha0, const double *hb,
                       double eps) {
    double ar[9], ha[3];
    for (int k = 0; k < 9; k++) ar[k] = fabs(r[k]) + 1e-12;
    for (int x = 0; x < 3; x++) ha[x] = ha0[x] + eps;
    for (int x = 0; x < 3; x++) {
        if (fabs(t[x]) > ha[x] + ar[3 * x] * hb[0] + ar[3 * x + 1] * hb[1] + ar[3 * x + 2] * hb[2])
            return 1;
    }
    for (int y = 0; y < 3; y++) {
        double tb = t[0] * r[y] + t[1] * r[3 + y] + t[2] * r[6 + y];
        if (fabs(tb) > ha[0] * ar[y] + ha[1] * ar[3 + y] + ha[2] * ar[6 + y] + hb[y]) return 1;
    }
    for (int x = 0; x < 3; x++) {
        int x1 = (x + 1) % 3, x2 = (x + 2) % 3;
        for (int y = 0; y < 3; y++) {
            int y1 = (y + 1) % 3, y2 = (y + 2) % 3;
            double lhs = fabs(t[x2] * r[3 * x1 + y] - t[x1] * r[3 * x2 + y]);
            double rhs = ha[x1] * ar[3 * x2 + y] + ha[x2] * ar[3 * x1 + y] +
                         hb[y1] * ar[3 * x + y2] + hb[y2] * ar[3 * x + y1];
            if (lhs > rhs) return 1;
        }
    }
    return 0;
}

/* Nodes na (of A) and nb (of B), nb's axes (rb) and centre (cb) already moved into A's frame:
 * apart by more than eps? Balls first (three products), the boxes' fifteen axes only if they meet. */
static int nodes_apart(const Node *na, const Node *nb, const double *rb, const double *cb,
                       double eps) {
    double d[3] = {cb[0] - na->c[0], cb[1] - na->c[1], cb[2] - na->c[2]};
    double reach = na->rad + nb->rad + eps;
    if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > reach * reach * (1.0 + 1e-12)) return 1;
    /* b's box in a's box frame: rotation Ra^T rb, centre Ra^T d. */
    double rel[9], t[3];
    for (int x = 0; x < 3; x++) {
        for (int y = 0; y < 3; y++) {
            rel[3 * x + y] = na->ax[x] * rb[y] + na->ax[3 + x] * rb[3 + y] + na->ax[6 + x] * rb[6 + y];
        }
        t[x] = na->ax[x] * d[0] + na->ax[3 + x] * d[1] + na->ax[6 + x] * d[2];
    }
    return boxes_apart(rel, t, na->h, nb->h, eps);
}

/* The interval triangle t (corners, 9 doubles) projects to on axis n (not normalised). */
static inline void span(const double *n, const double *t, double *lo, double *hi) {
    double x0 = n[0] * t[0] + n[1] * t[1] + n[2] * t[2];
    double x1 = n[0] * t[3] + n[1] * t[4] + n[2] * t[5];
    double x2 = n[0] * t[6] + n[1] * t[7] + n[2] * t[8];
    *lo = fmin(x0, fmin(x1, x2));
    *hi = fmax(x0, fmax(x1, x2));
}

/* 1 when the spans [alo, ahi] and [blo, bhi] on an axis with |n|^2 = nn leave a gap of more than
 * eps |n| (compared squared: no square root). A degenerate axis (nn == 0) projects everything to
 * 0 and so never shows a gap. */
static inline int spans_apart(double alo, double ahi, double blo, double bhi, double nn,
                              double eps2) {
    double gap = fmax(blo - ahi, alo - bhi);
    return gap > 0.0 && gap * gap > eps2 * nn;
}

/* 1 when triangles a and b (corners) are more than eps apart along axis n. */
static inline int axis_apart(const double *n, const double *a, const double *b, double eps2) {
    double alo, ahi, blo, bhi;
    span(n, a, &alo, &ahi);
    span(n, b, &blo, &bhi);
    return spans_apart(alo, ahi, blo, bhi, dot3(n, n), eps2);
}

/* A face normal: a's corners project to one value, so only b's span is computed. */
static inline int normal_apart(const double *n, const double *a, const double *b, double eps2) {
    double d = dot3(n, a), blo, bhi;
    span(n, b, &blo, &bhi);
    return spans_apart(d, d, blo, bhi, dot3(n, n), eps2);
}

/* 1 when triangles fa and fb (features, one frame) are proven more than eps apart by one of the
 * eleven separating axes of two triangles (two normals, nine edge-edge products). */
static int triangles_apart(const double *fa, const double *fb, double eps2) {
    if (normal_apart(fa + 18, fa, fb, eps2) || normal_apart(fb + 18, fb, fa, eps2)) return 1;
    double n[3];
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            cross3(fa + 9 + 3 * i, fb + 9 + 3 * j, n);
            if (axis_apart(n, fa, fb, eps2)) return 1;
        }
    }
    return 0;
}

static void scratch_free(Scratch *s) {
    free(s->tri);
    free(s->node);
    free(s->tri_stamp);
    free(s->node_stamp);
    free(s->pairs);
    memset(s, 0, sizeof(Scratch));
}

/* Room for meshes of up to most_tri triangles; 0, or -1 when out of memory. */
static int scratch_init(Scratch *s, int32_t most_tri) {
    size_t nt = (size_t)(most_tri > 0 ? most_tri : 1), nn = 2 * nt;
    memset(s, 0, sizeof(Scratch));
    s->cap = 256;
    s->tri = malloc(sizeof(double) * FEAT * nt);
    s->node = malloc(sizeof(double) * 12 * nn);
    s->tri_stamp = malloc(sizeof(int64_t) * nt);
    s->node_stamp = malloc(sizeof(int64_t) * nn);
    s->pairs = malloc(sizeof(int32_t) * 2 * s->cap);
    if (!s->tri || !s->node || !s->tri_stamp || !s->node_stamp || !s->pairs) {
        scratch_free(s);
        return -1;
    }
    for (size_t k = 0; k < nt; k++) s->tri_stamp[k] = -1;
    for (size_t k = 0; k < nn; k++) s->node_stamp[k] = -1;
    return 0;
}

static const double *moved_tri(Scratch *m, const Tree *b, int32_t tri, const double *r,
                               const double *p) {
    double *o = m->tri + FEAT * (size_t)tri;
    if (m->tri_stamp[tri] == m->now) return o;
    m->tri_stamp[tri] = m->now;
    const double *src = b->f + FEAT * (size_t)tri;
    for (int k = 0; k < 7; k++) {
        const double *x = src + 3 * k;
        double *y = o + 3 * k;
        for (int i = 0; i < 3; i++) y[i] = r[3 * i] * x[0] + r[3 * i + 1] * x[1] + r[3 * i + 2] * x[2];
        if (k < 3) {
            y[0] += p[0];
            y[1] += p[1];
            y[2] += p[2];
        }
    }
    return o;
}

/* Node id of B: its axes (9, r Rb) and centre (3, r cb + p) in A's frame. */
static const double *moved_node(Scratch *m, const Tree *b, int32_t id, const double *r,
                                const double *p) {
    double *o = m->node + 12 * (size_t)id;
    if (m->node_stamp[id] == m->now) return o;
    m->node_stamp[id] = m->now;
    const Node *nb = &b->nodes[id];
    for (int x = 0; x < 3; x++) {
        for (int y = 0; y < 3; y++) {
            o[3 * x + y] = r[3 * x] * nb->ax[y] + r[3 * x + 1] * nb->ax[3 + y] +
                           r[3 * x + 2] * nb->ax[6 + y];
        }
        o[9 + x] = r[3 * x] * nb->c[0] + r[3 * x + 1] * nb->c[1] + r[3 * x + 2] * nb->c[2] + p[x];
    }
    return o;
}

/* How far the projections of triangles a and b on axis n would have to move apart to separate,
 * over |n| (negative: they are separated by that much). A flat triangle projects to a point on its
 * own normal, so this is the depth of that point inside the other's interval, not the width of
 * the intersection (which would be zero). */
static inline double overlap_on(const double *n, const double *a, const double *b) {
    double alo, ahi, blo, bhi;
    span(n, a, &alo, &ahi);
    span(n, b, &blo, &bhi);
    return fmin(ahi - blo, bhi - alo) / sqrt(dot3(n, n));
}

/*
 * 1 when triangles fa and fb (features, one frame) are proven to cross: neither is degenerate,
 * they are not near-parallel, no pair of their edges is near-parallel, and their projections
 * overlap by more than eps on all eleven separating axes. Those axes are complete for two such
 * triangles, so no plane separates them: they intersect, and any exact test says so (eps covers
 * the rounding of the projections). 0 when not proven (nearly touching, parallel or degenerate:
 * coal decides).
 */
static int triangles_cross(const double *fa, const double *fb, double eps) {
    const double *na = fa + 18, *nb = fb + 18;
    double la = sqrt(dot3(na, na)), lb = sqrt(dot3(nb, nb)), n[3];
    if (!(la > 1e-300) || !(lb > 1e-300)) return 0;
    cross3(na, nb, n);
    if (!(sqrt(dot3(n, n)) > 1e-6 * la * lb)) return 0; /* near-parallel planes */
    if (!(overlap_on(na, fa, fb) > eps) || !(overlap_on(nb, fa, fb) > eps)) return 0;
    for (int i = 0; i < 3; i++) {
        const double *ea = fa + 9 + 3 * i;
        double lea = sqrt(dot3(ea, ea));
        for (int j = 0; j < 3; j++) {
            const double *eb = fb + 9 + 3 * j;
            cross3(ea, eb, n);
            if (!(sqrt(dot3(n, n)) > 1e-6 * lea * sqrt(dot3(eb, eb)))) return 0;
            if (!(overlap_on(n, fa, fb) > eps)) return 0;
        }
    }
    return 1;
}

/* 1 when meshes a and b are proven more than eps apart, 2 when two of their triangles are proven
 * to cross (the first pair that is not apart is tried); b's frame is (r, p) in a's frame. 0 when
 * neither is proven, -1 when out of memory. */
static int meshes_apart(const Tree *a, const Tree *b, const double *r, const double *p, double eps,
                        Scratch *st) {
    const double eps2 = eps * eps;
    size_t top = 1;
    st->pairs[0] = 0;
    st->pairs[1] = 0;
    st->now++;
    while (top > 0) {
        top--;
        const int32_t ia = st->pairs[2 * top], ib = st->pairs[2 * top + 1];
        const Node *na = &a->nodes[ia], *nb = &b->nodes[ib];
        const double *mb = moved_node(st, b, ib, r, p);
        if (nodes_apart(na, nb, mb, mb + 9, eps)) continue;
        int leaf_a = na->left < 0, leaf_b = nb->left < 0;
        if (leaf_a && leaf_b) {
            for (int32_t w = nb->first; w < nb->first + nb->count; w++) {
                const double *fb = moved_tri(st, b, b->order[w], r, p);
                for (int32_t u = na->first; u < na->first + na->count; u++) {
                    const double *fa = a->f + FEAT * (size_t)a->order[u];
                    if (!triangles_apart(fa, fb, eps2)) return triangles_cross(fa, fb, eps) ? 2 : 0;
                }
            }
            continue;
        }
        if (top + 2 > st->cap) {
            size_t cap = st->cap * 2;
            int32_t *p2 = realloc(st->pairs, sizeof(int32_t) * 2 * cap);
            if (p2 == NULL) return -1;
            st->pairs = p2;
            st->cap = cap;
        }
        /* Split the bigger box (a leaf cannot be split); size is the diagonal, not the volume,
         * which is zero for the flat boxes of planar patches. */
        if (leaf_b || (!leaf_a && na->rad >= nb->rad)) {
            st->pairs[2 * top] = na->left;
            st->pairs[2 * top + 1] = ib;
            st->pairs[2 * top + 2] = na->right;
            st->pairs[2 * top + 3] = ib;
        } else {
            st->pairs[2 * top] = ia;
            st->pairs[2 * top + 1] = nb->left;
            st->pairs[2 * top + 2] = ia;
            st->pairs[2 * top + 3] = nb->right;
        }
        top += 2;
    }
    return 1;
}

/* Candidate: geometry i against j at the poses pa, pb (row-major 4x4, world). */
static int candidate_apart(const MeshSet *s, int64_t i, int64_t j, const double *pa,
                           const double *pb, double eps, Scratch *st) {
    const Tree *ta = s->trees[i], *tb = s->trees[j];
    if (ta == NULL || tb == NULL) return 0;
    /* B in A: r = Ra^T Rb, p = Ra^T (tb - ta). */
    double r[9], p[3], d[3];
    for (int x = 0; x < 3; x++) d[x] = pb[4 * x + 3] - pa[4 * x + 3];
    for (int x = 0; x < 3; x++) {
        for (int y = 0; y < 3; y++) {
            r[3 * x + y] = pa[x] * pb[y] + pa[4 + x] * pb[4 + y] + pa[8 + x] * pb[8 + y];
        }
        p[x] = pa[x] * d[0] + pa[4 + x] * d[1] + pa[8 + x] * d[2];
    }
    return meshes_apart(ta, tb, r, p, eps, st);
}

/* ------------------------------------------------------------------ the narrow phase's walk */

/* What walk_rows does with a row's candidates: every colliding body pair, the first one only, or
 * every body pair not yet found colliding in any row (found is read and written). */
enum { WALK_ALL = 0, WALK_FIRST = 1, WALK_DROP_FOUND = 2 };

/* The arrays of one walk: candidates (rows[c], ks[c]) grouped by row (rows non-decreasing), the
 * geometry pairs (g1, g2) and their body pair (owner), geometry poses (ng per row, 4x4). */
typedef struct {
    const double *poses;
    ptrdiff_t ng;
    const int64_t *rows, *ks;
    ptrdiff_t nc;
    const int64_t *g1, *g2, *owner;
} WalkIn;

/* What a walk found: proven collisions (row, body pair) and the candidates left to coal
 * (indices into the candidates, in order); stamp (per body pair, -1 at first) and code (per
 * candidate) are working room. */
typedef struct {
    int64_t *hit_row, *hit_pair, *open, *stamp;
    uint8_t *code;
    ptrdiff_t n_hit, n_open;
} WalkOut;

/*
 * Every row's candidates proven in order, without a Python step between them (so the caller can
 * release the GIL for the whole block): a pair of meshes proven crossing is a collision of its
 * body pair, one proven apart is dropped, and what is neither (no proof, or not two meshes) is
 * left to coal, unless its body pair already collides in that row. WALK_FIRST ends a row at its
 * first proven collision, or at its first candidate left to coal (the caller asks coal, then
 * walks the rest of the row again when coal finds no collision). 0, or -1 when out of memory.
 */
static int walk_rows(const MeshSet *s, const WalkIn *in, uint8_t *found, double eps, int mode,
                     Scratch *st, WalkOut *out) {
    ptrdiff_t a = 0;
    while (a < in->nc) {
        const int64_t r = in->rows[a];
        ptrdiff_t b = a;
        while (b < in->nc && in->rows[b] == r) b++;
        int row_done = 0;
        for (ptrdiff_t c = a; c < b; c++) {
            const int64_t k = in->ks[c], p = in->owner[k], i = in->g1[k], j = in->g2[k];
            out->code[c] = 1; /* skipped, as if apart */
            if (out->stamp[p] == r || (mode == WALK_DROP_FOUND && found[p])) continue;
            int res = 0;
            if (s->trees[i] != NULL && s->trees[j] != NULL) {
                const double *pr = in->poses + r * in->ng * 16;
                res = candidate_apart(s, i, j, pr + i * 16, pr + j * 16, eps, st);
                if (res < 0) return -1;
            }
            out->code[c] = (uint8_t)res;
            if (res == 0 && mode == WALK_FIRST) {
                /* Coal decides this one before the row goes on: touching meshes, which the
                 * proofs cannot settle, are the costliest to prove, and coal often finds them
                 * colliding (the caller walks the rest of the row again if it does not). */
                out->open[out->n_open++] = c;
                row_done = 1;
                break;
            }
            if (res != 2) continue;
            out->stamp[p] = r;
            out->hit_row[out->n_hit] = r;
            out->hit_pair[out->n_hit] = p;
            out->n_hit++;
            if (mode == WALK_DROP_FOUND) found[p] = 1;
            if (mode == WALK_FIRST) {
                row_done = 1;
                break;
            }
        }
        if (!row_done) {
            for (ptrdiff_t c = a; c < b; c++) {
                if (out->code[c] != 0) continue;
                const int64_t p = in->owner[in->ks[c]];
                if (out->stamp[p] == r || (mode == WALK_DROP_FOUND && found[p])) continue;
                out->open[out->n_open++] = c;
            }
        }
        a = b;
    }
    return 0;
}

/* The point of triangle abc closest to p (Ericson, Real-Time Collision Detection, 5.1.5). */
static void point_triangle(const double *p, const double *a, const double *b, const double *c,
                           double *o) {
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    sub3(b, a, ab);
    sub3(c, a, ac);
    sub3(p, a, ap);
    double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        memcpy(o, a, 3 * sizeof(double));
        return;
    }
    sub3(p, b, bp);
    double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) {
        memcpy(o, b, 3 * sizeof(double));
        return;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        double v = d1 / (d1 - d3);
        for (int k = 0; k < 3; k++) o[k] = a[k] + v * ab[k];
        return;
    }
    sub3(p, c, cp);
    double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) {
        memcpy(o, c, 3 * sizeof(double));
        return;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        double w = d2 / (d2 - d6);
        for (int k = 0; k < 3; k++) o[k] = a[k] + w * ac[k];
        return;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; k++) o[k] = b[k] + w * (c[k] - b[k]);
        return;
    }
    double den = 1.0 / (va + vb + vc);
    double v = vb * den, w = vc * den;
    for (int k = 0; k < 3; k++) o[k] = a[k] + ab[k] * v + ac[k] * w;
}

/* 1 when point p (the mesh's frame) is within tol of one of the mesh's triangles, else 0; -1 when
 * out of memory. A box farther than tol from p is not entered. */
static int point_on_mesh(const Tree *t, const double *p, double tol, Scratch *st) {
    const double tol2 = tol * tol;
    size_t top = 1;
    st->pairs[0] = 0;
    while (top > 0) {
        const Node *n = &t->nodes[st->pairs[--top]];
        double d[3] = {p[0] - n->c[0], p[1] - n->c[1], p[2] - n->c[2]}, out = 0.0;
        for (int a = 0; a < 3; a++) {
            double excess = fabs(n->ax[a] * d[0] + n->ax[3 + a] * d[1] + n->ax[6 + a] * d[2]) -
                            n->h[a];
            if (excess > 0.0) out += excess * excess;
        }
        if (out > tol2) continue;
        if (n->left < 0) {
            for (int32_t s = n->first; s < n->first + n->count; s++) {
                const double *v = t->v + 9 * t->order[s];
                double q[3], g[3];
                point_triangle(p, v, v + 3, v + 6, q);
                sub3(p, q, g);
                if (dot3(g, g) <= tol2) return 1;
            }
            continue;
        }
        if (top + 2 > st->cap) {
            size_t cap = st->cap * 2;
            int32_t *p2 = realloc(st->pairs, sizeof(int32_t) * 2 * cap);
            if (p2 == NULL) return -1;
            st->pairs = p2;
            st->cap = cap;
        }
        st->pairs[top++] = n->left;
        st->pairs[top++] = n->right;
    }
    return 0;
}

#endif /* ROBOTSPEC_MESHCORE_KERNELS_H */
