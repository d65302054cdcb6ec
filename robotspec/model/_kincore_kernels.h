/*
 * The numeric kernels of robotspec.model._kincore: forward kinematics of a tree or a chain and
 * the oriented-box test of the collision broad phase, on plain C arrays.
 *
 * Why a file of its own: it includes no Python or numpy header, so it compiles with any C99
 * compiler for any platform (CI cross-compiles it for Windows with mingw-w64, warnings as
 * errors), whatever the Python glue (_kincore.c) needs. The glue includes this file into its
 * own translation unit, so the compiler inlines these static functions exactly as before the
 * split: the numbers and the speed do not depend on it.
 *
 * Poses are row-major 4x4 (numpy's layout); the last row is written as 0 0 0 1.
 */
#ifndef ROBOTSPEC_KINCORE_KERNELS_H
#define ROBOTSPEC_KINCORE_KERNELS_H

#include <math.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define KIND_FIXED 0
#define KIND_REVOLUTE 1
#define KIND_PRISMATIC 2

/* out(3x4) = a(3x4) * b(3x4), both read as 4x4 row-major with an implicit last row 0 0 0 1. */
static inline void mul34(const double *a, const double *b, double *out) {
    for (int r = 0; r < 3; r++) {
        const double a0 = a[4 * r], a1 = a[4 * r + 1], a2 = a[4 * r + 2], a3 = a[4 * r + 3];
        out[4 * r] = a0 * b[0] + a1 * b[4] + a2 * b[8];
        out[4 * r + 1] = a0 * b[1] + a1 * b[5] + a2 * b[9];
        out[4 * r + 2] = a0 * b[2] + a1 * b[6] + a2 * b[10];
        out[4 * r + 3] = a0 * b[3] + a1 * b[7] + a2 * b[11] + a3;
    }
}

static inline void sin_cos(double v, double *s, double *c) {
#if defined(__GLIBC__) && defined(_GNU_SOURCE)
    sincos(v, s, c);
#else
    *s = sin(v);
    *c = cos(v);
#endif
}

/*
 * Motion codes: the general kinds above, plus rotations about and translations along a frame
 * axis (x, y, z), which touch two columns or one translation instead of a full product. The
 * axis's sign is folded into the motion's multiplier and offset when the program is built.
 */
#define CODE_ROT_X 3
#define CODE_PRI_X 6

/* Apply one elementary motion to pose m in place: m = m * Rot(axis, v) or m * Trans(axis v). */
static inline void apply_motion(double *m, int code, const double *axis, double v) {
    if (code == KIND_REVOLUTE) {
        const double x = axis[0], y = axis[1], z = axis[2];
        double s, c;
        sin_cos(v, &s, &c);
        const double t = 1.0 - c;
        const double r00 = c + x * x * t, r01 = x * y * t - z * s, r02 = x * z * t + y * s;
        const double r10 = y * x * t + z * s, r11 = c + y * y * t, r12 = y * z * t - x * s;
        const double r20 = z * x * t - y * s, r21 = z * y * t + x * s, r22 = c + z * z * t;
        for (int r = 0; r < 3; r++) {
            const double a0 = m[4 * r], a1 = m[4 * r + 1], a2 = m[4 * r + 2];
            m[4 * r] = a0 * r00 + a1 * r10 + a2 * r20;
            m[4 * r + 1] = a0 * r01 + a1 * r11 + a2 * r21;
            m[4 * r + 2] = a0 * r02 + a1 * r12 + a2 * r22;
        }
    } else if (code == KIND_PRISMATIC) {
        const double dx = axis[0] * v, dy = axis[1] * v, dz = axis[2] * v;
        for (int r = 0; r < 3; r++) {
            m[4 * r + 3] += m[4 * r] * dx + m[4 * r + 1] * dy + m[4 * r + 2] * dz;
        }
    } else if (code >= CODE_ROT_X && code < CODE_ROT_X + 3) {
        /* About frame axis k: columns i = k+1 and j = k+2 (mod 3) mix. */
        const int k = code - CODE_ROT_X, i = (k + 1) % 3, j = (k + 2) % 3;
        double s, c;
        sin_cos(v, &s, &c);
        for (int r = 0; r < 3; r++) {
            const double ai = m[4 * r + i], aj = m[4 * r + j];
            m[4 * r + i] = c * ai + s * aj;
            m[4 * r + j] = c * aj - s * ai;
        }
    } else if (code >= CODE_PRI_X && code < CODE_PRI_X + 3) {
        const int k = code - CODE_PRI_X;
        m[3] += m[k] * v;
        m[7] += m[4 + k] * v;
        m[11] += m[8 + k] * v;
    }
}

/* out = a * b where b's rotation is the identity (a translation only). */
static inline void mul34_translate(const double *a, const double *b, double *out) {
    for (int r = 0; r < 3; r++) {
        const double a0 = a[4 * r], a1 = a[4 * r + 1], a2 = a[4 * r + 2];
        out[4 * r] = a0;
        out[4 * r + 1] = a1;
        out[4 * r + 2] = a2;
        out[4 * r + 3] = a0 * b[3] + a1 * b[7] + a2 * b[11] + a[4 * r + 3];
    }
}

static int is_identity_rotation(const double *o) {
    return o[0] == 1.0 && o[1] == 0.0 && o[2] == 0.0 && o[4] == 0.0 && o[5] == 1.0 &&
           o[6] == 0.0 && o[8] == 0.0 && o[9] == 0.0 && o[10] == 1.0;
}

/*
 * The fast code of a motion about/along a unit frame axis (sign folded into mul and off), or
 * the general kind.
 */
static int motion_code(int kind, const double *axis, double *mul, double *off) {
    if (kind != KIND_REVOLUTE && kind != KIND_PRISMATIC) return kind;
    for (int k = 0; k < 3; k++) {
        const double a = axis[k];
        if ((a == 1.0 || a == -1.0) && axis[(k + 1) % 3] == 0.0 && axis[(k + 2) % 3] == 0.0) {
            *mul *= a;
            *off *= a;
            return (kind == KIND_REVOLUTE ? CODE_ROT_X : CODE_PRI_X) + k;
        }
    }
    return kind;
}

static inline void last_row(double *m) {
    m[12] = 0.0;
    m[13] = 0.0;
    m[14] = 0.0;
    m[15] = 1.0;
}

static inline void identity(double *m) {
    memset(m, 0, 16 * sizeof(double));
    m[0] = m[5] = m[10] = m[15] = 1.0;
}

/*
 * A tree program: op k computes slot child[k] = slot parent[k] * origin[k] * motion_k(q).
 * Slot 0 is the root (identity); slots below n_out are the returned bodies, the others are
 * scratch (the intermediate frames of planar and floating connections).
 */
typedef struct {
    ptrdiff_t n_ops, n_slots, n_out, n_dof;
    int64_t *parent, *child, *kind, *dof;
    double *origin, *axis, *mul, *off;
    int *code, *translate; /* motion code (see motion_code), origin without rotation */
} Tree;

/* Every output pose of one configuration into out (n_out x 16); scratch has the other slots. */
static void tree_run(const Tree *t, const double *q, double *out, double *scratch) {
    identity(out);
    for (ptrdiff_t k = 0; k < t->n_ops; k++) {
        const int64_t p = t->parent[k], c = t->child[k];
        const double *pp = p < t->n_out ? out + 16 * p : scratch + 16 * (p - t->n_out);
        double *cp = c < t->n_out ? out + 16 * c : scratch + 16 * (c - t->n_out);
        if (t->translate[k]) {
            mul34_translate(pp, t->origin + 16 * k, cp);
        } else {
            mul34(pp, t->origin + 16 * k, cp);
        }
        const int code = t->code[k];
        if (code != KIND_FIXED) {
            apply_motion(cp, code, t->axis + 3 * k, q[t->dof[k]] * t->mul[k] + t->off[k]);
        }
        last_row(cp);
    }
}

/*
 * Why stage each sample in a small buffer when writing into a caller's array: a batch result
 * (100 MB for 10,000 PR2 samples) does not fit in any cache, and plain stores first read every
 * line they write. Computing a sample where it stays in cache and then streaming it out
 * (non-temporal stores, where the CPU has them) writes the result once. A fresh result is written
 * in place instead: its pages were just zeroed by the kernel and sit in cache, where streaming
 * would only evict them (measured: 36 against 25 ms for 10,000 PR2 samples).
 */
static void stream_copy(double *dst, const double *src, size_t n) {
#if defined(__SSE2__)
    if (((uintptr_t)dst & 15) == 0) {
        size_t k = 0;
        for (; k + 2 <= n; k += 2) _mm_stream_pd(dst + k, _mm_load_pd(src + k));
        for (; k < n; k++) dst[k] = src[k];
        return;
    }
#endif
    memcpy(dst, src, n * sizeof(double));
}

/* Samples 0 .. n of q into out; scratch holds the scratch slots, stage (16-byte aligned) one
 * sample's output when streaming. */
static void fk_run_batch(const Tree *t, const double *q, ptrdiff_t n, double *out, double *scratch,
                         double *stage, int stream) {
    const size_t width = 16 * (size_t)t->n_out;
    for (ptrdiff_t i = 0; i < n; i++) {
        if (stream) {
            tree_run(t, q + i * t->n_dof, stage, scratch);
            stream_copy(out + i * (ptrdiff_t)width, stage, width);
        } else {
            tree_run(t, q + i * t->n_dof, out + i * (ptrdiff_t)width, scratch);
        }
    }
#if defined(__SSE2__)
    if (stream) _mm_sfence();
#endif
}

/*
 * A chain program: T = pre[0] m_0(q) pre[1] m_1(q) ... pre[n-1] m_{n-1}(q) post, where pre[i]
 * holds the fixed transforms before elementary motion i; col[i] is the Jacobian column motion i
 * adds to (mimic joints add to their leader's column, scaled by mul[i]).
 */
typedef struct {
    ptrdiff_t n, n_cols, n_dof;
    int64_t *kind, *dof, *col;
    double *pre, *post, *axis, *mul, *off;
} Chain;

static void chain_run(const Chain *c, const double *qv, double *o) {
    double t[16], u[16];
    identity(t);
    for (ptrdiff_t i = 0; i < c->n; i++) {
        mul34(t, c->pre + 16 * i, u);
        apply_motion(u, (int)c->kind[i], c->axis + 3 * i, qv[c->dof[i]] * c->mul[i] + c->off[i]);
        memcpy(t, u, 12 * sizeof(double));
    }
    mul34(t, c->post, o);
    last_row(o);
}

/* The chain's Jacobian (6 x n_cols, row-major, zeroed by the caller) at qv into j; z and p hold
 * 3 * n doubles each (every motion's world axis and origin). */
static void chain_jacobian_run(const Chain *c, const double *qv, double *z, double *p, double *j) {
    double t[16], u[16], tip[16];
    identity(t);
    for (ptrdiff_t i = 0; i < c->n; i++) {
        mul34(t, c->pre + 16 * i, u);
        const double *a = c->axis + 3 * i;
        for (int r = 0; r < 3; r++) {
            z[3 * i + r] = u[4 * r] * a[0] + u[4 * r + 1] * a[1] + u[4 * r + 2] * a[2];
            p[3 * i + r] = u[4 * r + 3];
        }
        apply_motion(u, (int)c->kind[i], a, qv[c->dof[i]] * c->mul[i] + c->off[i]);
        memcpy(t, u, 12 * sizeof(double));
    }
    mul34(t, c->post, tip);
    const ptrdiff_t w = c->n_cols;
    for (ptrdiff_t i = 0; i < c->n; i++) {
        const double *zi = z + 3 * i, *pi = p + 3 * i, m = c->mul[i];
        const ptrdiff_t k = c->col[i];
        if (c->kind[i] == KIND_REVOLUTE) {
            const double dx = tip[3] - pi[0], dy = tip[7] - pi[1], dz = tip[11] - pi[2];
            j[0 * w + k] += m * (zi[1] * dz - zi[2] * dy);
            j[1 * w + k] += m * (zi[2] * dx - zi[0] * dz);
            j[2 * w + k] += m * (zi[0] * dy - zi[1] * dx);
            j[3 * w + k] += m * zi[0];
            j[4 * w + k] += m * zi[1];
            j[5 * w + k] += m * zi[2];
        } else {
            j[0 * w + k] += m * zi[0];
            j[1 * w + k] += m * zi[1];
            j[2 * w + k] += m * zi[2];
        }
    }
}

/*
 * Geometries (each on a body, with a body-frame box) and the geometry pairs to test. The broad
 * phase keeps a (sample, pair) when the boxes' world-aligned bounds come within the margin and
 * no separating axis of the two oriented boxes (15 axes) parts them by more than the margin:
 * both tests are conservative, so coal's narrow phase decides every answer.
 */
typedef struct {
    ptrdiff_t n_geom, n_pair, n_body;
    int64_t *body, *g1, *g2;
    double *body_T_geom, *center, *half;
} Geoms;

static int obb_separated(const double *a, const double *ha, const double *b, const double *hb) {
    /* a, b: world poses (4x4 rows) of the box frames; ha, hb: inflated half extents. */
    double r[3][3], ar[3][3], t[3], d[3];
    for (int x = 0; x < 3; x++) d[x] = b[4 * x + 3] - a[4 * x + 3];
    for (int x = 0; x < 3; x++) {
        for (int y = 0; y < 3; y++) {
            r[x][y] = a[x] * b[y] + a[4 + x] * b[4 + y] + a[8 + x] * b[8 + y];
            ar[x][y] = fabs(r[x][y]) + 1e-9;
        }
        t[x] = a[x] * d[0] + a[4 + x] * d[1] + a[8 + x] * d[2];
    }
    for (int x = 0; x < 3; x++) {
        if (fabs(t[x]) > ha[x] + ar[x][0] * hb[0] + ar[x][1] * hb[1] + ar[x][2] * hb[2]) return 1;
        double tb = t[0] * r[0][x] + t[1] * r[1][x] + t[2] * r[2][x];
        if (fabs(tb) > ha[0] * ar[0][x] + ha[1] * ar[1][x] + ha[2] * ar[2][x] + hb[x]) return 1;
    }
    for (int x = 0; x < 3; x++) {
        int x1 = (x + 1) % 3, x2 = (x + 2) % 3;
        for (int y = 0; y < 3; y++) {
            int y1 = (y + 1) % 3, y2 = (y + 2) % 3;
            double lhs = fabs(t[x2] * r[x1][y] - t[x1] * r[x2][y]);
            double rhs = ha[x1] * ar[x2][y] + ha[x2] * ar[x1][y] + hb[y1] * ar[x][y2] +
                         hb[y2] * ar[x][y1];
            if (lhs > rhs) return 1;
        }
    }
    return 0;
}

/* One sample's geometry poses (n_geom x 16) from its body poses bs into gs, and each
 * geometry's world-aligned bounds: lo (less the margin) and hi, 3 doubles per geometry. */
static void geoms_place(const Geoms *g, const double *bs, double *gs, double margin, double *lo,
                        double *hi) {
    for (ptrdiff_t i = 0; i < g->n_geom; i++) {
        const double *b = bs + 16 * g->body[i];
        double *o = gs + 16 * i;
        mul34(b, g->body_T_geom + 16 * i, o);
        last_row(o);
        const double *c = g->center + 3 * i, *h = g->half + 3 * i;
        for (int a = 0; a < 3; a++) {
            const double *row = b + 4 * a;
            double cen = row[0] * c[0] + row[1] * c[1] + row[2] * c[2] + row[3];
            double hw = fabs(row[0]) * h[0] + fabs(row[1]) * h[1] + fabs(row[2]) * h[2];
            lo[3 * i + a] = cen - hw - margin;
            hi[3 * i + a] = cen + hw;
        }
    }
}

/* 1 when pair k may come within the margin at the sample whose body poses are bs (bounds lo, hi
 * from geoms_place): the bounds overlap and no axis of the two oriented boxes parts them. */
static int pair_may_touch(const Geoms *g, const double *bs, double margin, const double *lo,
                          const double *hi, ptrdiff_t k) {
    const int64_t i = g->g1[k], j = g->g2[k];
    int apart = 0;
    for (int a = 0; a < 3 && !apart; a++) {
        apart = !(lo[3 * i + a] <= hi[3 * j + a] && lo[3 * j + a] <= hi[3 * i + a]);
    }
    if (apart) return 0;
    /* Box frames: the body pose with the box centre as origin. */
    double fa[16], fb[16], ha[3], hb[3];
    const double *ba = bs + 16 * g->body[i], *bb = bs + 16 * g->body[j];
    memcpy(fa, ba, 12 * sizeof(double));
    memcpy(fb, bb, 12 * sizeof(double));
    const double *ca = g->center + 3 * i, *cb = g->center + 3 * j;
    for (int a = 0; a < 3; a++) {
        fa[4 * a + 3] = ba[4 * a] * ca[0] + ba[4 * a + 1] * ca[1] + ba[4 * a + 2] * ca[2] +
                        ba[4 * a + 3];
        fb[4 * a + 3] = bb[4 * a] * cb[0] + bb[4 * a + 1] * cb[1] + bb[4 * a + 2] * cb[2] +
                        bb[4 * a + 3];
        ha[a] = g->half[3 * i + a] + margin / 2.0;
        hb[a] = g->half[3 * j + a] + margin / 2.0;
    }
    return !obb_separated(fa, ha, fb, hb);
}

#endif /* ROBOTSPEC_KINCORE_KERNELS_H */
