/*
 * robotspec.collision._meshcore: proofs that two triangle meshes are apart, in C.
 *
 * Why: coal tests a mesh pair by descending both bounding-volume trees and running GJK on every
 * pair of leaf triangles whose volumes come within its break distance. Pairs that nearly touch
 * in every configuration (a gripper palm in its forearm's wrist clevis, 0.4 mm apart) then cost
 * 200-300 us a test, and the collision matrix runs 10,000 of them per pair. Most such tests end
 * with "apart", which a separating axis proves in a few dozen operations a box or triangle pair.
 *
 * What it answers: for each candidate (sample, geometry pair) of the broad phase whose both
 * geometries are meshes, 1 when every pair of triangles is proven apart by more than eps (a
 * separating axis with that much room, found box by box down an axis-aligned box tree), 0 when
 * it could not prove it (they may touch: the caller runs coal, whose answer stands). A 1 is
 * therefore never a guess: the two surfaces are more than eps apart, so coal, whose collision
 * test compares the surfaces' distance with the security margin, says "no collision" too when
 * eps exceeds margin plus its own tolerance (the caller's choice).
 *
 * Poses are row-major 4x4 (numpy's layout). Trees live in one capsule per checker.
 *
 * This file is the glue (arguments, the capsule, numpy results), on CPython's limited API
 * (setup.py); the trees and proofs are in _meshcore_kernels.h, which includes no Python header.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "_meshcore_kernels.h"

/*
 * The version of the calls between this module and robotspec/collision/meshcore.py (its
 * INTERFACE): bump both whenever an entry point's arguments or results change. The module exports
 * it as INTERFACE, and robotspec/accel.py refuses a module whose number differs (a stale build).
 */
#define MESHCORE_INTERFACE 3

/* A tree from vertices (V, 3) and triangles (T, 3); NULL with an exception set on bad input. */
static Tree *tree_new(PyObject *vobj, PyObject *fobj) {
    /* One conversion at a time: numpy is never called with the previous one's error set. */
    PyArrayObject *va = (PyArrayObject *)PyArray_FROMANY(vobj, NPY_DOUBLE, 2, 2, NPY_ARRAY_IN_ARRAY);
    PyArrayObject *fa = va == NULL ? NULL
                                   : (PyArrayObject *)PyArray_FROMANY(fobj, NPY_INT64, 2, 2,
                                                                      NPY_ARRAY_IN_ARRAY);
    Tree *t = NULL;
    Keyed *scratch = NULL;
    if (va == NULL || fa == NULL) goto fail;
    if (PyArray_DIM(va, 1) != 3 || PyArray_DIM(fa, 1) != 3 || PyArray_DIM(fa, 0) < 1 ||
        PyArray_DIM(fa, 0) > INT32_MAX / 4) {
        PyErr_SetString(PyExc_ValueError, "a mesh needs vertices (V, 3) and triangles (T >= 1, 3)");
        goto fail;
    }
    npy_intp nv = PyArray_DIM(va, 0), nt = PyArray_DIM(fa, 0);
    const double *v = PyArray_DATA(va);
    const int64_t *f = PyArray_DATA(fa);
    t = calloc(1, sizeof(Tree));
    if (t == NULL) goto nomem;
    t->n_tri = (int32_t)nt;
    t->v = malloc(sizeof(double) * 9 * (size_t)nt);
    t->f = malloc(sizeof(double) * FEAT * (size_t)nt);
    t->order = malloc(sizeof(int32_t) * (size_t)nt);
    t->nodes = malloc(sizeof(Node) * 2 * (size_t)nt);
    scratch = malloc(sizeof(Keyed) * (size_t)nt);
    if (t->v == NULL || t->f == NULL || t->order == NULL || t->nodes == NULL || scratch == NULL)
        goto nomem;
    for (npy_intp k = 0; k < nt; k++) {
        for (int c = 0; c < 3; c++) {
            int64_t i = f[3 * k + c];
            if (i < 0 || i >= nv) {
                PyErr_SetString(PyExc_ValueError, "a triangle refers to a vertex out of range");
                goto fail;
            }
            for (int a = 0; a < 3; a++) {
                double x = v[3 * i + a];
                if (!isfinite(x)) {
                    PyErr_SetString(PyExc_ValueError, "a mesh vertex is not finite");
                    goto fail;
                }
                t->v[9 * k + 3 * c + a] = x;
            }
        }
        t->order[k] = (int32_t)k;
        features(t->v + 9 * k, t->f + FEAT * k);
    }
    if (tree_build(t, scratch) != 0) goto nomem;
    free(scratch);
    Py_DECREF(va);
    Py_DECREF(fa);
    return t;
nomem:
    PyErr_NoMemory();
fail:
    free(scratch);
    tree_free(t);
    Py_XDECREF((PyObject *)va);
    Py_XDECREF((PyObject *)fa);
    return NULL;
}

static void set_free(PyObject *capsule) {
    MeshSet *s = PyCapsule_GetPointer(capsule, "robotspec.meshset");
    if (s == NULL) return;
    for (Py_ssize_t i = 0; i < s->n; i++) tree_free(s->trees[i]);
    if (s->one != NULL) scratch_free(s->one);
    free(s->one);
    for (ptrdiff_t k = 0; k < s->n_spare; k++) {
        scratch_free(s->spare[k]);
        free(s->spare[k]);
    }
    free(s->spare);
    free(s->trees);
    free(s);
}

/* mesh_set([(vertices, triangles) or None, ...]) -> capsule
 * The set is complete (trees and apart_one's scratch) before the capsule owns it, so a failure
 * frees each allocation exactly once: by hand before the capsule exists, by its destructor after. */
static PyObject *py_mesh_set(PyObject *self, PyObject *args) {
    PyObject *seq;
    if (!PyArg_ParseTuple(args, "O", &seq)) return NULL;
    PyObject *fast = PySequence_Fast(seq, "mesh_set needs a sequence");
    if (fast == NULL) return NULL;
    Py_ssize_t n = PySequence_Size(fast);
    MeshSet *s = calloc(1, sizeof(MeshSet));
    Tree **trees = calloc((size_t)(n > 0 ? n : 1), sizeof(Tree *));
    Scratch *one = calloc(1, sizeof(Scratch));
    if (s == NULL || trees == NULL || one == NULL) {
        free(s);
        free(trees);
        free(one);
        Py_DECREF(fast);
        return PyErr_NoMemory();
    }
    s->trees = trees;
    s->one = one; /* zeroed: scratch_free is safe on it before scratch_init */
    s->n = n;
    PyObject *cap = PyCapsule_New(s, "robotspec.meshset", set_free);
    if (cap == NULL) {
        free(one);
        free(trees);
        free(s);
        Py_DECREF(fast);
        return NULL;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        /* Borrowed, as PySequence_Fast_GET_ITEM gives it (not in the limited API). */
        PyObject *item = PyList_Check(fast) ? PyList_GetItem(fast, i) : PyTuple_GetItem(fast, i);
        if (item == Py_None) continue;
        PyObject *vobj, *fobj;
        if (!PyTuple_Check(item) || PyTuple_Size(item) != 2) {
            PyErr_SetString(PyExc_TypeError, "mesh_set: each mesh is (vertices, triangles) or None");
            Py_DECREF(fast);
            Py_DECREF(cap);
            return NULL;
        }
        vobj = PyTuple_GetItem(item, 0);
        fobj = PyTuple_GetItem(item, 1);
        if ((s->trees[i] = tree_new(vobj, fobj)) == NULL) {
            Py_DECREF(fast);
            Py_DECREF(cap);
            return NULL;
        }
    }
    Py_DECREF(fast);
    s->most_tri = 1;
    for (Py_ssize_t i = 0; i < n; i++) {
        if (s->trees[i] != NULL && s->trees[i]->n_tri > s->most_tri) s->most_tri = s->trees[i]->n_tri;
    }
    if (scratch_init(s->one, s->most_tri) != 0) {
        Py_DECREF(cap);
        return PyErr_NoMemory();
    }
    return cap;
}

/* ------------------------------------------------------------------------------- queries */

/* The set in a capsule made by mesh_set, else NULL with a TypeError naming it (as the numpy
 * fallback raises for anything but its own sets; PyCapsule_GetPointer's is a ValueError). */
static MeshSet *set_of(PyObject *cap) {
    if (!PyCapsule_IsValid(cap, "robotspec.meshset")) {
        PyErr_SetString(PyExc_TypeError, "expected a mesh set (from mesh_set())");
        return NULL;
    }
    return PyCapsule_GetPointer(cap, "robotspec.meshset");
}

/*
 * A scratch for one call that releases the GIL: a spare one of the set's, else a new one; NULL
 * with MemoryError set. Taken and given back with the GIL held (the GIL is the pool's lock: this
 * module declares no free-threading support, so a free-threaded CPython enables the GIL for it).
 * Why a pool: a scratch is sized for the set's largest mesh and its stamps must start cleared,
 * which cost a single query more than its proofs when made per call.
 */
static Scratch *scratch_take(MeshSet *s) {
    if (s->n_spare > 0) return s->spare[--s->n_spare];
    Scratch *st = calloc(1, sizeof(Scratch));
    if (st == NULL || scratch_init(st, s->most_tri) != 0) {
        free(st);
        PyErr_NoMemory();
        return NULL;
    }
    return st;
}

/* st back to the set's spares (GIL held); freed when there is no room to keep it. */
static void scratch_give(MeshSet *s, Scratch *st) {
    if (s->n_spare == s->cap_spare) {
        ptrdiff_t cap = s->cap_spare > 0 ? 2 * s->cap_spare : 4;
        Scratch **grown = realloc(s->spare, sizeof(Scratch *) * (size_t)cap);
        if (grown == NULL) {
            scratch_free(st);
            free(st);
            return;
        }
        s->spare = grown;
        s->cap_spare = cap;
    }
    s->spare[s->n_spare++] = st;
}

/*
 * apart(set, poses (N, G, 4, 4), rows (K,), pairs (K,), g1 (Q,), g2 (Q,), eps) -> uint8 (K,)
 * Candidate c is (sample rows[c], geometry pair pairs[c] = (g1, g2)); poses are the geometries'
 * world poses. 1: both are meshes, proven more than eps apart; 2: proven to cross (two triangles
 * intersect); 0: neither proven (or not meshes).
 */
static PyObject *py_apart(PyObject *self, PyObject *args) {
    PyObject *cap, *pobj, *robj, *kobj, *g1obj, *g2obj;
    double eps;
    if (!PyArg_ParseTuple(args, "OOOOOOd", &cap, &pobj, &robj, &kobj, &g1obj, &g2obj, &eps))
        return NULL;
    MeshSet *s = set_of(cap);
    if (s == NULL) return NULL;
    if (!(eps >= 1e-9) || !isfinite(eps)) {
        /* At least a nanometre: the squared comparisons leave rounding no room below that. */
        PyErr_SetString(PyExc_ValueError, "eps must be finite and >= 1e-9");
        return NULL;
    }
    /* One conversion at a time, in argument order: numpy is never called with an error set, and
     * the first bad argument is the one reported (as by the numpy fallback). */
    PyArrayObject *poses = NULL, *rows = NULL, *ks = NULL, *g1 = NULL, *g2 = NULL;
    poses = (PyArrayObject *)PyArray_FROMANY(pobj, NPY_DOUBLE, 4, 4, NPY_ARRAY_IN_ARRAY);
    if (poses != NULL)
        rows = (PyArrayObject *)PyArray_FROMANY(robj, NPY_INT64, 1, 1, NPY_ARRAY_IN_ARRAY);
    if (rows != NULL)
        ks = (PyArrayObject *)PyArray_FROMANY(kobj, NPY_INT64, 1, 1, NPY_ARRAY_IN_ARRAY);
    if (ks != NULL)
        g1 = (PyArrayObject *)PyArray_FROMANY(g1obj, NPY_INT64, 1, 1, NPY_ARRAY_IN_ARRAY);
    if (g1 != NULL)
        g2 = (PyArrayObject *)PyArray_FROMANY(g2obj, NPY_INT64, 1, 1, NPY_ARRAY_IN_ARRAY);
    PyArrayObject *out = NULL;
    Scratch *st = NULL;
    if (poses == NULL || rows == NULL || ks == NULL || g1 == NULL || g2 == NULL) goto done;
    npy_intp n = PyArray_DIM(poses, 0), ng = PyArray_DIM(poses, 1), nc = PyArray_DIM(rows, 0);
    npy_intp nq = PyArray_DIM(g1, 0);
    if (ng != s->n || PyArray_DIM(poses, 2) != 4 || PyArray_DIM(poses, 3) != 4 ||
        PyArray_DIM(ks, 0) != nc || PyArray_DIM(g2, 0) != nq) {
        PyErr_SetString(PyExc_ValueError, "apart: arrays of the wrong shape");
        goto done;
    }
    const int64_t *rv = PyArray_DATA(rows), *kv = PyArray_DATA(ks);
    const int64_t *g1v = PyArray_DATA(g1), *g2v = PyArray_DATA(g2);
    for (npy_intp c = 0; c < nc; c++) {
        if (rv[c] < 0 || rv[c] >= n || kv[c] < 0 || kv[c] >= nq || g1v[kv[c]] < 0 ||
            g1v[kv[c]] >= ng || g2v[kv[c]] < 0 || g2v[kv[c]] >= ng) {
            PyErr_SetString(PyExc_ValueError, "apart: a candidate is out of range");
            goto done;
        }
    }
    npy_intp od[1] = {nc};
    out = (PyArrayObject *)PyArray_ZEROS(1, od, NPY_UINT8, 0);
    if (out == NULL) goto done;
    if ((st = scratch_take(s)) == NULL) {
        Py_CLEAR(out);
        goto done;
    }
    const double *pv = PyArray_DATA(poses);
    uint8_t *ov = PyArray_DATA(out);
    int oom = 0;
    Py_BEGIN_ALLOW_THREADS
    for (npy_intp c = 0; c < nc && !oom; c++) {
        const int64_t i = g1v[kv[c]], j = g2v[kv[c]];
        int res = candidate_apart(s, i, j, pv + (rv[c] * ng + i) * 16, pv + (rv[c] * ng + j) * 16,
                                  eps, st);
        if (res < 0) oom = 1;
        ov[c] = res > 0 ? (uint8_t)res : 0;
    }
    Py_END_ALLOW_THREADS
    if (oom) {
        Py_CLEAR(out);
        PyErr_NoMemory();
    }
done:
    if (st != NULL) scratch_give(s, st);
    Py_XDECREF((PyObject *)poses);
    Py_XDECREF((PyObject *)rows);
    Py_XDECREF((PyObject *)ks);
    Py_XDECREF((PyObject *)g1);
    Py_XDECREF((PyObject *)g2);
    return (PyObject *)out;
}

/* 1 when obj is an array the core may read in place as float64: a numpy array of native byte
 * order, aligned and C-contiguous; else 0 with a TypeError saying which. */
static int borrowable(PyObject *obj, const char *who, const char *what) {
    PyArrayObject *a = (PyArrayObject *)obj;
    if (!PyArray_Check(obj) || PyArray_TYPE(a) != NPY_DOUBLE) {
        PyErr_Format(PyExc_TypeError, "%s: %s must be a float64 numpy array", who, what);
        return 0;
    }
    if (!PyArray_ISNOTSWAPPED(a) || !PyArray_ISALIGNED(a) || !PyArray_IS_C_CONTIGUOUS(a)) {
        PyErr_Format(PyExc_TypeError, "%s: %s must be native-order, aligned and C-contiguous",
                     who, what);
        return 0;
    }
    return 1;
}

/*
 * The caller's (N, G, 4, 4) geometry poses, borrowed (no copy: the one-by-one calls run per
 * candidate), or NULL with an exception when they are not float64, C-contiguous and G = the set's
 * geometries.
 */
static PyArrayObject *geometry_poses(PyObject *pobj, const MeshSet *s, const char *who) {
    PyArrayObject *poses = (PyArrayObject *)pobj;
    if (!borrowable(pobj, who, "poses")) return NULL;
    if (PyArray_NDIM(poses) != 4 || PyArray_DIM(poses, 1) != s->n || PyArray_DIM(poses, 2) != 4 ||
        PyArray_DIM(poses, 3) != 4) {
        PyErr_Format(PyExc_ValueError, "%s: poses of the wrong shape (N, G, 4, 4)", who);
        return NULL;
    }
    return poses;
}

/*
 * apart_one(set, poses (N, G, 4, 4) float64 C-contiguous, row, i, j, eps) -> 0, 1 or 2 (as apart)
 * One candidate, for a caller that tests candidates one by one and stops early (an "any
 * collision" query). Holds the GIL: its scratch lives in the set.
 */
static PyObject *py_apart_one(PyObject *self, PyObject *args) {
    PyObject *cap, *pobj;
    Py_ssize_t row, i, j;
    double eps;
    if (!PyArg_ParseTuple(args, "OOnnnd", &cap, &pobj, &row, &i, &j, &eps)) return NULL;
    MeshSet *s = set_of(cap);
    if (s == NULL) return NULL;
    PyArrayObject *poses = geometry_poses(pobj, s, "apart_one");
    if (poses == NULL) return NULL;
    if (row < 0 || row >= PyArray_DIM(poses, 0) || i < 0 || i >= s->n || j < 0 || j >= s->n) {
        PyErr_SetString(PyExc_ValueError, "apart_one: a candidate is out of range");
        return NULL;
    }
    if (!(eps >= 1e-9) || !isfinite(eps)) {
        PyErr_SetString(PyExc_ValueError, "eps must be finite and >= 1e-9");
        return NULL;
    }
    const double *pv = PyArray_DATA(poses);
    int res = candidate_apart(s, i, j, pv + (row * s->n + i) * 16, pv + (row * s->n + j) * 16, eps,
                              s->one);
    if (res < 0) return PyErr_NoMemory();
    return PyLong_FromLong(res);
}

/* ------------------------------------------------------------------------ the narrow walk */

/* 1 when obj is a 1-D array the core reads in place as int64 (or uint8 when `byte`): its data in
 * *data and length in *len; else 0 with a TypeError naming it. */
static int flat_array(PyObject *obj, int byte, const char *what, void **data, npy_intp *len) {
    PyArrayObject *a = (PyArrayObject *)obj;
    if (!PyArray_Check(obj) || PyArray_TYPE(a) != (byte ? NPY_UINT8 : NPY_INT64) ||
        PyArray_NDIM(a) != 1 || !PyArray_ISNOTSWAPPED(a) || !PyArray_ISALIGNED(a) ||
        !PyArray_IS_C_CONTIGUOUS(a)) {
        PyErr_Format(PyExc_TypeError, "walk: %s must be a C-contiguous 1-D %s numpy array", what,
                     byte ? "uint8" : "int64");
        return 0;
    }
    *data = PyArray_DATA(a);
    *len = PyArray_DIM(a, 0);
    return 1;
}

/* A new int64 array (n,) holding v[0 .. n). */
static PyObject *int64_array(const int64_t *v, npy_intp n) {
    PyArrayObject *a = (PyArrayObject *)PyArray_SimpleNew(1, &n, NPY_INT64);
    if (a != NULL && n > 0) memcpy(PyArray_DATA(a), v, sizeof(int64_t) * (size_t)n);
    return (PyObject *)a;
}

/*
 * walk(set, poses (N, G, 4, 4), rows (K,), pairs (K,), g1 (Q,), g2 (Q,), owner (Q,), found (P,),
 *      eps, mode) -> (hit rows (H,), hit body pairs (H,), open candidates (M,))
 * The narrow phase of a block of broad-phase candidates (rows non-decreasing), in one call with
 * the GIL released (see walk_rows): which (row, body pair)s are proven to collide, and which
 * candidates (indices into rows/pairs, in order) coal must decide. mode 0: every colliding body
 * pair; 1: a row ends at its first proven collision or at its first candidate left to coal; 2:
 * body pairs set in found (uint8, written) are skipped and set when proven. Arrays are numpy's, read in place (no conversion: the checker made them).
 * Why: the narrow phase once ran in Python between C calls, holding the GIL, so two threads
 * checking a batch took turns (issue 34).
 */
static PyObject *py_walk(PyObject *self, PyObject *args) {
    PyObject *cap, *pobj, *robj, *kobj, *g1obj, *g2obj, *oobj, *fobj;
    double eps;
    int mode;
    if (!PyArg_ParseTuple(args, "OOOOOOOOdi", &cap, &pobj, &robj, &kobj, &g1obj, &g2obj, &oobj,
                          &fobj, &eps, &mode))
        return NULL;
    MeshSet *s = set_of(cap);
    if (s == NULL) return NULL;
    PyArrayObject *poses = geometry_poses(pobj, s, "walk");
    if (poses == NULL) return NULL;
    npy_intp nc, nk, nq, nq2, nq3, np_;
    void *rv, *kv, *g1v, *g2v, *ov, *fv;
    if (!flat_array(robj, 0, "rows", &rv, &nc) || !flat_array(kobj, 0, "pairs", &kv, &nk) ||
        !flat_array(g1obj, 0, "g1", &g1v, &nq) || !flat_array(g2obj, 0, "g2", &g2v, &nq2) ||
        !flat_array(oobj, 0, "owner", &ov, &nq3) || !flat_array(fobj, 1, "found", &fv, &np_))
        return NULL;
    const int64_t *rows = rv, *ks = kv, *g1 = g1v, *g2 = g2v, *owner = ov;
    uint8_t *found = fv;
    if (!PyArray_ISWRITEABLE((PyArrayObject *)fobj)) {
        PyErr_SetString(PyExc_ValueError, "walk: found must be writeable");
        return NULL;
    }
    if (!(eps >= 1e-9) || !isfinite(eps)) {
        PyErr_SetString(PyExc_ValueError, "eps must be finite and >= 1e-9");
        return NULL;
    }
    if (mode < WALK_ALL || mode > WALK_DROP_FOUND) {
        PyErr_SetString(PyExc_ValueError, "walk: mode must be 0, 1 or 2");
        return NULL;
    }
    if (nk != nc || nq2 != nq || nq3 != nq) {
        PyErr_SetString(PyExc_ValueError, "walk: arrays of the wrong shape");
        return NULL;
    }
    const npy_intp n = PyArray_DIM(poses, 0), ng = s->n;
    for (npy_intp q = 0; q < nq; q++) {
        if (g1[q] < 0 || g1[q] >= ng || g2[q] < 0 || g2[q] >= ng || owner[q] < 0 ||
            owner[q] >= np_) {
            PyErr_SetString(PyExc_ValueError, "walk: a geometry pair is out of range");
            return NULL;
        }
    }
    for (npy_intp c = 0; c < nc; c++) {
        if (rows[c] < 0 || rows[c] >= n || ks[c] < 0 || ks[c] >= nq ||
            (c > 0 && rows[c] < rows[c - 1])) {
            PyErr_SetString(PyExc_ValueError,
                            "walk: a candidate is out of range or out of row order");
            return NULL;
        }
    }
    size_t room = (size_t)(nc > 0 ? nc : 1);
    WalkIn in = {PyArray_DATA(poses), ng, rows, ks, nc, g1, g2, owner};
    WalkOut out;
    memset(&out, 0, sizeof(WalkOut));
    out.hit_row = malloc(sizeof(int64_t) * room);
    out.hit_pair = malloc(sizeof(int64_t) * room);
    out.open = malloc(sizeof(int64_t) * room);
    out.stamp = malloc(sizeof(int64_t) * (size_t)(np_ > 0 ? np_ : 1));
    out.code = malloc(room);
    PyObject *result = NULL;
    Scratch *st = NULL;
    if (!out.hit_row || !out.hit_pair || !out.open || !out.stamp || !out.code) {
        PyErr_NoMemory();
        goto done;
    }
    if ((st = scratch_take(s)) == NULL) goto done;
    for (npy_intp p = 0; p < np_; p++) out.stamp[p] = -1;
    int failed;
    Py_BEGIN_ALLOW_THREADS
    failed = walk_rows(s, &in, found, eps, mode, st, &out);
    Py_END_ALLOW_THREADS
    scratch_give(s, st);
    if (failed) {
        PyErr_NoMemory();
        goto done;
    }
    PyObject *hr = int64_array(out.hit_row, out.n_hit);
    PyObject *hp = hr == NULL ? NULL : int64_array(out.hit_pair, out.n_hit);
    PyObject *op = hp == NULL ? NULL : int64_array(out.open, out.n_open);
    if (op != NULL) result = PyTuple_Pack(3, hr, hp, op);
    Py_XDECREF(hr);
    Py_XDECREF(hp);
    Py_XDECREF(op);
done:
    free(out.hit_row);
    free(out.hit_pair);
    free(out.open);
    free(out.stamp);
    free(out.code);
    return result;
}

/* ------------------------------------------------------------------------ points on a mesh */

/*
 * on_surface(set, poses (N, G, 4, 4), row, g, point (3,), tol) -> bool
 * Whether a point (world frame) lies within tol of geometry g's mesh at sample row: the test that
 * a convex hull's closest point is one of the mesh's own (see SelfCollisionChecker.distances).
 * False when g is not a mesh of the set.
 */
static PyObject *py_on_surface(PyObject *self, PyObject *args) {
    PyObject *cap, *pobj, *xobj;
    Py_ssize_t row, g;
    double tol;
    if (!PyArg_ParseTuple(args, "OOnnOd", &cap, &pobj, &row, &g, &xobj, &tol)) return NULL;
    MeshSet *s = set_of(cap);
    if (s == NULL) return NULL;
    PyArrayObject *poses = geometry_poses(pobj, s, "on_surface");
    if (poses == NULL) return NULL;
    PyArrayObject *xa = (PyArrayObject *)xobj;
    if (!borrowable(xobj, "on_surface", "point")) return NULL;
    if (PyArray_SIZE(xa) != 3) {
        PyErr_SetString(PyExc_ValueError, "on_surface: point of the wrong shape (3 values)");
        return NULL;
    }
    if (row < 0 || row >= PyArray_DIM(poses, 0) || g < 0 || g >= s->n || !(tol >= 0.0) ||
        !isfinite(tol)) {
        PyErr_SetString(PyExc_ValueError, "on_surface: row, geometry or tolerance out of range");
        return NULL;
    }
    const Tree *t = s->trees[g];
    if (t == NULL) Py_RETURN_FALSE;
    const double *m = (const double *)PyArray_DATA(poses) + (row * s->n + g) * 16;
    const double *x = PyArray_DATA(xa);
    double d[3] = {x[0] - m[3], x[1] - m[7], x[2] - m[11]}, p[3];
    for (int a = 0; a < 3; a++) p[a] = m[a] * d[0] + m[4 + a] * d[1] + m[8 + a] * d[2];
    int res = point_on_mesh(t, p, tol, s->one);
    if (res < 0) return PyErr_NoMemory();
    return PyBool_FromLong(res);
}

/* ---------------------------------------------------------------------------------- module */

static PyMethodDef methods[] = {
    {"mesh_set", py_mesh_set, METH_VARARGS, "Box trees of the meshes of a checker."},
    {"apart", py_apart, METH_VARARGS, "Per candidate: 1 when its two meshes are proven apart."},
    {"apart_one", py_apart_one, METH_VARARGS, "Whether one candidate's meshes are proven apart."},
    {"walk", py_walk, METH_VARARGS, "The narrow phase's proofs of a block: hits and what coal decides."},
    {"on_surface", py_on_surface, METH_VARARGS, "Whether a point lies on a geometry's mesh."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_meshcore", "Proofs that two triangle meshes are apart, in C.", -1,
    methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__meshcore(void) {
    import_array();
    PyObject *m = PyModule_Create(&module);
    if (m != NULL && PyModule_AddIntConstant(m, "INTERFACE", MESHCORE_INTERFACE) != 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
