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
#define MESHCORE_INTERFACE 1

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
static const MeshSet *set_of(PyObject *cap) {
    if (!PyCapsule_IsValid(cap, "robotspec.meshset")) {
        PyErr_SetString(PyExc_TypeError, "expected a mesh set (from mesh_set())");
        return NULL;
    }
    return PyCapsule_GetPointer(cap, "robotspec.meshset");
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
    const MeshSet *s = set_of(cap);
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
    Scratch st;
    memset(&st, 0, sizeof(Scratch));
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
    if (scratch_init(&st, s->most_tri) != 0) {
        Py_CLEAR(out);
        PyErr_NoMemory();
        goto done;
    }
    const double *pv = PyArray_DATA(poses);
    uint8_t *ov = PyArray_DATA(out);
    int oom = 0;
    Py_BEGIN_ALLOW_THREADS
    for (npy_intp c = 0; c < nc && !oom; c++) {
        const int64_t i = g1v[kv[c]], j = g2v[kv[c]];
        int res = candidate_apart(s, i, j, pv + (rv[c] * ng + i) * 16, pv + (rv[c] * ng + j) * 16,
                                  eps, &st);
        if (res < 0) oom = 1;
        ov[c] = res > 0 ? (uint8_t)res : 0;
    }
    Py_END_ALLOW_THREADS
    if (oom) {
        Py_CLEAR(out);
        PyErr_NoMemory();
    }
done:
    scratch_free(&st);
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
    const MeshSet *s = set_of(cap);
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
    const MeshSet *s = set_of(cap);
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
