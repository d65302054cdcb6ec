/*
 * robotspec.model._kincore: forward kinematics, chain Jacobians and the collision broad phase
 * of a compiled world, in C.
 *
 * Why C: one configuration of a real robot is a few thousand floating-point operations, so in
 * numpy (a hundred array calls of ~1 us each) or through a binding that copies poses out one by
 * one, the call overhead is the whole cost. Here one Python call does the whole query and
 * returns a fresh numpy array. The layout of every table is decided in Python
 * (robotspec/model/program.py); this file only runs it. No state is kept between calls: tables
 * live in capsules owned by the Python objects that built them.
 *
 * Poses are row-major 4x4 (numpy's layout); the last row is written as 0 0 0 1.
 *
 * Portable C99 (no threads, no variable-length arrays, compiler extensions only behind #if): a
 * large batch is split over Python threads by robotspec/model/kincore.py, each slice one call
 * that runs with the GIL released. An accelerator only: robotspec/model/_kincore_py.py gives the
 * same answers in numpy when this file could not be built.
 *
 * This file is the glue (arguments, tables in capsules, numpy results), on CPython's limited API
 * (setup.py); the arithmetic is in _kincore_kernels.h, which includes no Python or numpy header.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "_kincore_kernels.h"

/*
 * The version of the calls between this module and robotspec/model/kincore.py (its INTERFACE):
 * bump both whenever an entry point's arguments, results or table layout change. The module
 * exports it as INTERFACE, and robotspec/accel.py refuses a module whose number differs (a
 * stale build left beside newer Python files) instead of letting it misread the tables.
 */
#define KINCORE_INTERFACE 1

/* ------------------------------------------------------------------------------- helpers */

static int64_t *copy_i64(PyObject *obj, Py_ssize_t want, const char *what) {
    PyArrayObject *a = (PyArrayObject *)PyArray_FROMANY(obj, NPY_INT64, 1, 1, NPY_ARRAY_IN_ARRAY);
    if (a == NULL) return NULL;
    if (PyArray_SIZE(a) != want) {
        PyErr_Format(PyExc_ValueError, "%s: expected %zd values, got %zd", what, want,
                     (Py_ssize_t)PyArray_SIZE(a));
        Py_DECREF(a);
        return NULL;
    }
    int64_t *out = malloc(sizeof(int64_t) * (size_t)(want > 0 ? want : 1));
    if (out == NULL) {
        Py_DECREF(a);
        PyErr_NoMemory();
        return NULL;
    }
    if (want > 0) memcpy(out, PyArray_DATA(a), sizeof(int64_t) * (size_t)want);
    Py_DECREF(a);
    return out;
}

static double *copy_f64(PyObject *obj, Py_ssize_t want, const char *what) {
    PyArrayObject *a = (PyArrayObject *)PyArray_FROMANY(obj, NPY_DOUBLE, 0, 0, NPY_ARRAY_IN_ARRAY);
    if (a == NULL) return NULL;
    if (PyArray_SIZE(a) != want) {
        PyErr_Format(PyExc_ValueError, "%s: expected %zd values, got %zd", what, want,
                     (Py_ssize_t)PyArray_SIZE(a));
        Py_DECREF(a);
        return NULL;
    }
    double *out = malloc(sizeof(double) * (size_t)(want > 0 ? want : 1));
    if (out == NULL) {
        Py_DECREF(a);
        PyErr_NoMemory();
        return NULL;
    }
    if (want > 0) memcpy(out, PyArray_DATA(a), sizeof(double) * (size_t)want);
    Py_DECREF(a);
    return out;
}

/* A configuration (or batch) as a contiguous float64 array of the given rank and width. */
static PyArrayObject *as_config(PyObject *obj, int ndim, Py_ssize_t width) {
    PyArrayObject *a;
    /* The common case first: an array this core can read as it is (what PyArray_FROMANY would
     * hand back itself, with a new reference), without numpy's conversion machinery, which is
     * a fifth of a small query. Anything else is converted, and refused, by numpy as before. */
    if (PyArray_Check(obj) && PyArray_TYPE((PyArrayObject *)obj) == NPY_DOUBLE &&
        PyArray_NDIM((PyArrayObject *)obj) == ndim &&
        PyArray_ISNOTSWAPPED((PyArrayObject *)obj) &&
        PyArray_CHKFLAGS((PyArrayObject *)obj, NPY_ARRAY_IN_ARRAY)) {
        Py_INCREF(obj);
        a = (PyArrayObject *)obj;
    } else {
        a = (PyArrayObject *)PyArray_FROMANY(obj, NPY_DOUBLE, ndim, ndim, NPY_ARRAY_IN_ARRAY);
        if (a == NULL) return NULL;
    }
    if (PyArray_DIM(a, ndim - 1) != width) {
        PyErr_SetString(PyExc_ValueError, "configuration has the wrong number of values");
        Py_DECREF(a);
        return NULL;
    }
    const double *v = PyArray_DATA(a);
    npy_intp n = PyArray_SIZE(a);
    for (npy_intp i = 0; i < n; i++) {
        if (!isfinite(v[i])) {
            PyErr_SetString(PyExc_ValueError, "configuration contains NaN or infinite values");
            Py_DECREF(a);
            return NULL;
        }
    }
    return a;
}

/* The table in a capsule made by this module's constructor, else NULL with a TypeError naming it
 * (PyCapsule_GetPointer's own error is a ValueError about capsules, which the caller never made;
 * the numpy fallback raises this same TypeError for anything but its own tables). */
static void *table(PyObject *cap, const char *name, const char *what) {
    void *p = PyCapsule_GetPointer(cap, name); /* one test of the type and the name */
    if (p == NULL) {
        PyErr_Clear();
        PyErr_Format(PyExc_TypeError, "expected %s", what);
    }
    return p;
}

/* The argument count of a METH_FASTCALL entry point, refused as PyArg_ParseTuple refuses it.
 * Why fast calls for the single-configuration queries (fk, chain_fk, chain_jacobian): they cost
 * about a microsecond, and packing the arguments into a tuple and parsing it back is a tenth. */
static int arg_count(const char *name, Py_ssize_t nargs, Py_ssize_t want) {
    if (nargs == want) return 1;
    PyErr_Format(PyExc_TypeError, "%s() takes exactly %zd arguments (%zd given)", name, want,
                 nargs);
    return 0;
}

#define TREE_OF(cap) ((const Tree *)table((cap), "robotspec.tree", "a tree program (from tree())"))
#define CHAIN_OF(cap) \
    ((const Chain *)table((cap), "robotspec.chain", "a chain program (from chain())"))
#define GEOMS_OF(cap) \
    ((const Geoms *)table((cap), "robotspec.geoms", "a geometry table (from geoms())"))

/* ------------------------------------------------------------------------------- the tree */

static void tree_free(PyObject *capsule) {
    Tree *t = PyCapsule_GetPointer(capsule, "robotspec.tree");
    if (t == NULL) return;
    free(t->parent);
    free(t->child);
    free(t->kind);
    free(t->dof);
    free(t->origin);
    free(t->axis);
    free(t->mul);
    free(t->off);
    free(t->code);
    free(t->translate);
    free(t);
}

static PyObject *py_tree(PyObject *self, PyObject *args) {
    PyObject *parent, *child, *kind, *origin, *axis, *dof, *mul, *off;
    Py_ssize_t n_slots, n_out, n_dof;
    if (!PyArg_ParseTuple(args, "OOOOOOOOnnn", &parent, &child, &kind, &origin, &axis, &dof,
                          &mul, &off, &n_slots, &n_out, &n_dof))
        return NULL;
    Py_ssize_t n = PyObject_Length(parent);
    if (n < 0) return NULL;
    /* The root is output slot 0; every scratch slot is some row's child. */
    if (n_out < 1 || n_slots < n_out || n_slots - n_out > n || n_dof < 0) {
        PyErr_SetString(PyExc_ValueError, "tree program: slot or DOF counts out of range");
        return NULL;
    }
    Tree *t = calloc(1, sizeof(Tree));
    if (t == NULL) return PyErr_NoMemory();
    t->n_ops = n;
    t->n_slots = n_slots;
    t->n_out = n_out;
    t->n_dof = n_dof;
    PyObject *cap = PyCapsule_New(t, "robotspec.tree", tree_free);
    if (cap == NULL) {
        free(t);
        return NULL;
    }
    if (!(t->parent = copy_i64(parent, n, "parent")) || !(t->child = copy_i64(child, n, "child")) ||
        !(t->kind = copy_i64(kind, n, "kind")) || !(t->dof = copy_i64(dof, n, "dof")) ||
        !(t->origin = copy_f64(origin, 16 * n, "origin")) ||
        !(t->axis = copy_f64(axis, 3 * n, "axis")) || !(t->mul = copy_f64(mul, n, "mul")) ||
        !(t->off = copy_f64(off, n, "off"))) {
        Py_DECREF(cap);
        return NULL;
    }
    for (Py_ssize_t k = 0; k < n; k++) {
        if (t->parent[k] < 0 || t->parent[k] >= n_slots || t->child[k] <= 0 ||
            t->child[k] >= n_slots || t->parent[k] == t->child[k] ||
            (t->kind[k] != KIND_FIXED && (t->dof[k] < 0 || t->dof[k] >= n_dof))) {
            PyErr_SetString(PyExc_ValueError, "tree program refers to a slot or DOF out of range");
            Py_DECREF(cap);
            return NULL;
        }
        if (t->kind[k] < KIND_FIXED || t->kind[k] > KIND_PRISMATIC) {
            PyErr_SetString(PyExc_ValueError, "tree program has a motion kind out of range");
            Py_DECREF(cap);
            return NULL;
        }
    }
    /* Parents first: a row reads only the root or a slot an earlier row wrote (never memory
     * that no row set). */
    char *written = calloc((size_t)n_slots, 1);
    if (written == NULL) {
        Py_DECREF(cap);
        return PyErr_NoMemory();
    }
    written[0] = 1;
    for (Py_ssize_t k = 0; k < n; k++) {
        if (!written[t->parent[k]]) {
            free(written);
            PyErr_SetString(PyExc_ValueError, "tree program reads a slot before a row writes it");
            Py_DECREF(cap);
            return NULL;
        }
        written[t->child[k]] = 1;
    }
    Py_ssize_t unset = 1;
    while (unset < n_out && written[unset]) unset++;
    free(written);
    if (unset < n_out) { /* its pose would be whatever the allocator left there */
        PyErr_SetString(PyExc_ValueError, "tree program leaves a body's pose unset");
        Py_DECREF(cap);
        return NULL;
    }
    t->code = malloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
    t->translate = malloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
    if (t->code == NULL || t->translate == NULL) {
        Py_DECREF(cap);
        return PyErr_NoMemory();
    }
    for (Py_ssize_t k = 0; k < n; k++) {
        t->code[k] = motion_code((int)t->kind[k], t->axis + 3 * k, t->mul + k, t->off + k);
        t->translate[k] = is_identity_rotation(t->origin + 16 * k);
    }
    return cap;
}

static PyObject *py_fk(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (!arg_count("fk", nargs, 2)) return NULL;
    PyObject *cap = args[0], *qobj = args[1];
    const Tree *t = TREE_OF(cap);
    if (t == NULL) return NULL;
    PyArrayObject *q = as_config(qobj, 1, t->n_dof);
    if (q == NULL) return NULL;
    npy_intp dims[3] = {t->n_out, 4, 4};
    PyArrayObject *out = (PyArrayObject *)PyArray_SimpleNew(3, dims, NPY_DOUBLE);
    if (out == NULL) {
        Py_DECREF(q);
        return NULL;
    }
    double stack[16 * 32];
    Py_ssize_t n_scratch = t->n_slots - t->n_out;
    double *scratch = n_scratch <= 32 ? stack : malloc(sizeof(double) * 16 * (size_t)n_scratch);
    if (scratch == NULL) {
        Py_DECREF(q);
        Py_DECREF(out);
        return PyErr_NoMemory();
    }
    tree_run(t, PyArray_DATA(q), PyArray_DATA(out), scratch);
    if (scratch != stack) free(scratch);
    Py_DECREF(q);
    return (PyObject *)out;
}

/* The caller's out array when it is one the core may write as native float64 poses (N, B, 4, 4):
 * TypeError for the wrong type, byte order or alignment, ValueError for the wrong shape. */
static int check_out(PyObject *oobj, npy_intp n, Py_ssize_t n_out) {
    PyArrayObject *out = (PyArrayObject *)oobj;
    if (!PyArray_Check(oobj) || PyArray_TYPE(out) != NPY_DOUBLE || !PyArray_ISNOTSWAPPED(out) ||
        !PyArray_ISALIGNED(out) || !PyArray_IS_C_CONTIGUOUS(out) || !PyArray_ISWRITEABLE(out)) {
        PyErr_SetString(PyExc_TypeError, "out must be a writeable, aligned, native-order "
                                         "C-contiguous float64 array (N, B, 4, 4)");
        return -1;
    }
    if (PyArray_NDIM(out) != 4 || PyArray_DIM(out, 0) != n || PyArray_DIM(out, 1) != n_out ||
        PyArray_DIM(out, 2) != 4 || PyArray_DIM(out, 3) != 4) {
        PyErr_SetString(PyExc_ValueError, "out must be a writeable, aligned, native-order "
                                          "C-contiguous float64 array (N, B, 4, 4)");
        return -1;
    }
    return 0;
}

/*
 * fk_batch(tree, q (N, D), out=None, stream=False) -> poses (N, B, 4, 4), into out when given
 * One loop over the samples with the GIL released, so robotspec/model/kincore.py runs slices of a
 * batch on several Python threads at once. stream: write through a cached stage with
 * non-temporal stores (for a caller's array, see stream_copy).
 */
static PyObject *py_fk_batch(PyObject *self, PyObject *args) {
    PyObject *cap, *qobj, *oobj = Py_None;
    int stream = 0;
    if (!PyArg_ParseTuple(args, "OO|Op", &cap, &qobj, &oobj, &stream)) return NULL;
    const Tree *t = TREE_OF(cap);
    if (t == NULL) return NULL;
    PyArrayObject *q = as_config(qobj, 2, t->n_dof);
    if (q == NULL) return NULL;
    npy_intp n = PyArray_DIM(q, 0);
    npy_intp dims[4] = {n, t->n_out, 4, 4};
    PyArrayObject *out;
    if (oobj == Py_None) {
        out = (PyArrayObject *)PyArray_SimpleNew(4, dims, NPY_DOUBLE);
        if (out == NULL) {
            Py_DECREF(q);
            return NULL;
        }
    } else {
        /* The caller's array, written in place: a batch loop then reuses its pages. */
        if (check_out(oobj, n, t->n_out) != 0) {
            Py_DECREF(q);
            return NULL;
        }
        out = (PyArrayObject *)oobj;
        Py_INCREF((PyObject *)out);
    }
    Py_ssize_t n_scratch = t->n_slots - t->n_out;
    /* Scratch slots, then a 16-byte aligned stage of one sample's output. */
    size_t per = 16 * (size_t)(n_scratch > 0 ? n_scratch : 1) + 16 * (size_t)t->n_out + 2;
    double *scratch = malloc(sizeof(double) * per);
    if (scratch == NULL) {
        Py_DECREF(q);
        Py_DECREF(out);
        return PyErr_NoMemory();
    }
    double *stage = scratch + 16 * (size_t)(n_scratch > 0 ? n_scratch : 1);
    if (((uintptr_t)stage & 15) != 0) stage++;
    const double *qv = PyArray_DATA(q);
    double *ov = PyArray_DATA(out);
    Py_BEGIN_ALLOW_THREADS
    fk_run_batch(t, qv, n, ov, scratch, stage, stream);
    Py_END_ALLOW_THREADS
    free(scratch);
    Py_DECREF(q);
    return (PyObject *)out;
}

/* tree_size(tree) -> (bodies returned, degrees of freedom) */
static PyObject *py_tree_size(PyObject *self, PyObject *args) {
    PyObject *cap;
    if (!PyArg_ParseTuple(args, "O", &cap)) return NULL;
    const Tree *t = TREE_OF(cap);
    if (t == NULL) return NULL;
    return Py_BuildValue("nn", (Py_ssize_t)t->n_out, (Py_ssize_t)t->n_dof);
}

/* ------------------------------------------------------------------------------ a chain */

static void chain_free(PyObject *capsule) {
    Chain *c = PyCapsule_GetPointer(capsule, "robotspec.chain");
    if (c == NULL) return;
    free(c->kind);
    free(c->dof);
    free(c->col);
    free(c->pre);
    free(c->post);
    free(c->axis);
    free(c->mul);
    free(c->off);
    free(c);
}

static PyObject *py_chain(PyObject *self, PyObject *args) {
    PyObject *pre, *post, *kind, *axis, *dof, *mul, *off, *col;
    Py_ssize_t n_cols, n_dof;
    if (!PyArg_ParseTuple(args, "OOOOOOOOnn", &pre, &post, &kind, &axis, &dof, &mul, &off, &col,
                          &n_cols, &n_dof))
        return NULL;
    Py_ssize_t n = PyObject_Length(kind);
    if (n < 0) return NULL;
    if (n_cols < 0 || n_dof < 0) {
        PyErr_SetString(PyExc_ValueError, "chain program: column or DOF count out of range");
        return NULL;
    }
    Chain *c = calloc(1, sizeof(Chain));
    if (c == NULL) return PyErr_NoMemory();
    c->n = n;
    c->n_cols = n_cols;
    c->n_dof = n_dof;
    PyObject *cap = PyCapsule_New(c, "robotspec.chain", chain_free);
    if (cap == NULL) {
        free(c);
        return NULL;
    }
    if (!(c->pre = copy_f64(pre, 16 * n, "pre")) || !(c->post = copy_f64(post, 16, "post")) ||
        !(c->kind = copy_i64(kind, n, "kind")) || !(c->axis = copy_f64(axis, 3 * n, "axis")) ||
        !(c->dof = copy_i64(dof, n, "dof")) || !(c->mul = copy_f64(mul, n, "mul")) ||
        !(c->off = copy_f64(off, n, "off")) || !(c->col = copy_i64(col, n, "col"))) {
        Py_DECREF(cap);
        return NULL;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        if (c->dof[i] < 0 || c->dof[i] >= n_dof || c->col[i] < 0 || c->col[i] >= n_cols ||
            (c->kind[i] != KIND_REVOLUTE && c->kind[i] != KIND_PRISMATIC)) {
            PyErr_SetString(PyExc_ValueError, "chain program refers to a DOF out of range");
            Py_DECREF(cap);
            return NULL;
        }
    }
    return cap;
}

static PyObject *py_chain_fk(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (!arg_count("chain_fk", nargs, 2)) return NULL;
    PyObject *cap = args[0], *qobj = args[1];
    const Chain *c = CHAIN_OF(cap);
    if (c == NULL) return NULL;
    PyArrayObject *q = as_config(qobj, 1, c->n_dof);
    if (q == NULL) return NULL;
    npy_intp dims[2] = {4, 4};
    PyArrayObject *out = (PyArrayObject *)PyArray_SimpleNew(2, dims, NPY_DOUBLE);
    if (out != NULL) chain_run(c, PyArray_DATA(q), PyArray_DATA(out));
    Py_DECREF(q);
    return (PyObject *)out;
}

static PyObject *py_chain_fk_batch(PyObject *self, PyObject *args) {
    PyObject *cap, *qobj;
    if (!PyArg_ParseTuple(args, "OO", &cap, &qobj)) return NULL;
    const Chain *c = CHAIN_OF(cap);
    if (c == NULL) return NULL;
    PyArrayObject *q = as_config(qobj, 2, c->n_dof);
    if (q == NULL) return NULL;
    npy_intp n = PyArray_DIM(q, 0);
    npy_intp dims[3] = {n, 4, 4};
    PyArrayObject *out = (PyArrayObject *)PyArray_SimpleNew(3, dims, NPY_DOUBLE);
    if (out != NULL) {
        const double *qv = PyArray_DATA(q);
        double *ov = PyArray_DATA(out);
        Py_BEGIN_ALLOW_THREADS
        for (npy_intp i = 0; i < n; i++) chain_run(c, qv + i * c->n_dof, ov + 16 * i);
        Py_END_ALLOW_THREADS
    }
    Py_DECREF(q);
    return (PyObject *)out;
}

static PyObject *py_chain_jacobian(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (!arg_count("chain_jacobian", nargs, 2)) return NULL;
    PyObject *cap = args[0], *qobj = args[1];
    const Chain *c = CHAIN_OF(cap);
    if (c == NULL) return NULL;
    PyArrayObject *q = as_config(qobj, 1, c->n_dof);
    if (q == NULL) return NULL;
    const double *qv = PyArray_DATA(q);
    npy_intp dims[2] = {6, c->n_cols};
    PyArrayObject *out = (PyArrayObject *)PyArray_ZEROS(2, dims, NPY_DOUBLE, 0);
    double zbuf[3 * 64], pbuf[3 * 64];
    double *z = c->n <= 64 ? zbuf : malloc(sizeof(double) * 3 * (size_t)c->n);
    double *p = c->n <= 64 ? pbuf : malloc(sizeof(double) * 3 * (size_t)c->n);
    if (out == NULL || z == NULL || p == NULL) {
        if (z != zbuf) free(z);
        if (p != pbuf) free(p);
        Py_DECREF(q);
        Py_XDECREF((PyObject *)out);
        return out == NULL ? NULL : PyErr_NoMemory();
    }
    chain_jacobian_run(c, qv, z, p, PyArray_DATA(out));
    if (z != zbuf) free(z);
    if (p != pbuf) free(p);
    Py_DECREF(q);
    return (PyObject *)out;
}

/* ------------------------------------------------------------------ collision broad phase */

static void geoms_free(PyObject *capsule) {
    Geoms *g = PyCapsule_GetPointer(capsule, "robotspec.geoms");
    if (g == NULL) return;
    free(g->body);
    free(g->g1);
    free(g->g2);
    free(g->body_T_geom);
    free(g->center);
    free(g->half);
    free(g);
}

static PyObject *py_geoms(PyObject *self, PyObject *args) {
    PyObject *body, *btg, *center, *half, *g1, *g2;
    Py_ssize_t n_body;
    if (!PyArg_ParseTuple(args, "OOOOOOn", &body, &btg, &center, &half, &g1, &g2, &n_body))
        return NULL;
    Py_ssize_t ng = PyObject_Length(body);
    if (ng < 0) return NULL;
    Py_ssize_t np_ = PyObject_Length(g1); /* not called with body's error set */
    if (np_ < 0) return NULL;
    Geoms *g = calloc(1, sizeof(Geoms));
    if (g == NULL) return PyErr_NoMemory();
    g->n_geom = ng;
    g->n_pair = np_;
    g->n_body = n_body;
    PyObject *cap = PyCapsule_New(g, "robotspec.geoms", geoms_free);
    if (cap == NULL) {
        free(g);
        return NULL;
    }
    if (!(g->body = copy_i64(body, ng, "body")) ||
        !(g->body_T_geom = copy_f64(btg, 16 * ng, "body_T_geom")) ||
        !(g->center = copy_f64(center, 3 * ng, "center")) ||
        !(g->half = copy_f64(half, 3 * ng, "half")) || !(g->g1 = copy_i64(g1, np_, "g1")) ||
        !(g->g2 = copy_i64(g2, np_, "g2"))) {
        Py_DECREF(cap);
        return NULL;
    }
    for (Py_ssize_t i = 0; i < ng; i++) {
        if (g->body[i] < 0 || g->body[i] >= n_body) {
            PyErr_SetString(PyExc_ValueError, "geometry on a body out of range");
            Py_DECREF(cap);
            return NULL;
        }
    }
    for (Py_ssize_t k = 0; k < np_; k++) {
        if (g->g1[k] < 0 || g->g1[k] >= ng || g->g2[k] < 0 || g->g2[k] >= ng) {
            PyErr_SetString(PyExc_ValueError, "geometry pair out of range");
            Py_DECREF(cap);
            return NULL;
        }
    }
    return cap;
}

/*
 * broad(geoms, body_poses (N, B, 4, 4) or (B, 4, 4), margin, mask or None)
 *   -> (rows int64 (K,), pairs int64 (K,), geometry poses (N, G, 4, 4))
 * The candidates come sample by sample, pairs in order; mask (uint8 per pair) drops pairs.
 */
static PyObject *py_broad(PyObject *self, PyObject *args) {
    PyObject *cap, *pobj, *mobj;
    double margin;
    if (!PyArg_ParseTuple(args, "OOdO", &cap, &pobj, &margin, &mobj)) return NULL;
    const Geoms *g = GEOMS_OF(cap);
    if (g == NULL) return NULL;
    PyArrayObject *poses = (PyArrayObject *)PyArray_FROMANY(pobj, NPY_DOUBLE, 3, 4,
                                                            NPY_ARRAY_IN_ARRAY);
    if (poses == NULL) return NULL;
    int nd = PyArray_NDIM(poses);
    npy_intp n = nd == 4 ? PyArray_DIM(poses, 0) : 1;
    if (PyArray_DIM(poses, nd - 3) != g->n_body || PyArray_DIM(poses, nd - 2) != 4 ||
        PyArray_DIM(poses, nd - 1) != 4) {
        Py_DECREF(poses);
        PyErr_SetString(PyExc_ValueError, "body poses have the wrong shape");
        return NULL;
    }
    PyArrayObject *mask = NULL;
    if (mobj != Py_None) {
        mask = (PyArrayObject *)PyArray_FROMANY(mobj, NPY_UINT8, 1, 1, NPY_ARRAY_IN_ARRAY);
        if (mask == NULL || PyArray_SIZE(mask) != g->n_pair) {
            Py_DECREF(poses);
            Py_XDECREF((PyObject *)mask);
            if (mask != NULL) PyErr_SetString(PyExc_ValueError, "pair mask has the wrong size");
            return NULL;
        }
    }
    npy_intp gdims[4] = {n, g->n_geom, 4, 4};
    PyArrayObject *gp = (PyArrayObject *)PyArray_SimpleNew(4, gdims, NPY_DOUBLE);
    size_t cap_k = 64;
    npy_intp nk = 0;
    int64_t *rows = malloc(sizeof(int64_t) * cap_k), *ks = malloc(sizeof(int64_t) * cap_k);
    double *lo = malloc(sizeof(double) * 3 * (size_t)(g->n_geom > 0 ? g->n_geom : 1));
    double *hi = malloc(sizeof(double) * 3 * (size_t)(g->n_geom > 0 ? g->n_geom : 1));
    int failed = gp == NULL || rows == NULL || ks == NULL || lo == NULL || hi == NULL;
    if (!failed) {
        /* Plain C over arrays this call holds: other threads run meanwhile (batched checks on
           several threads, issue 34). */
        Py_BEGIN_ALLOW_THREADS
        const double *bp = PyArray_DATA(poses);
        double *gv = PyArray_DATA(gp);
        const uint8_t *mv = mask == NULL ? NULL : PyArray_DATA(mask);
        for (npy_intp s = 0; s < n && !failed; s++) {
            const double *bs = bp + s * g->n_body * 16;
            double *gs = gv + s * g->n_geom * 16;
            geoms_place(g, bs, gs, margin, lo, hi);
            for (Py_ssize_t k = 0; k < g->n_pair; k++) {
                if (mv != NULL && !mv[k]) continue;
                if (!pair_may_touch(g, bs, margin, lo, hi, k)) continue;
                if ((size_t)nk == cap_k) {
                    cap_k *= 2;
                    int64_t *r2 = realloc(rows, sizeof(int64_t) * cap_k);
                    if (r2 != NULL) rows = r2;
                    int64_t *k2 = realloc(ks, sizeof(int64_t) * cap_k);
                    if (k2 != NULL) ks = k2;
                    if (r2 == NULL || k2 == NULL) {
                        failed = 1;
                        break;
                    }
                }
                rows[nk] = s;
                ks[nk] = k;
                nk++;
            }
        }
        Py_END_ALLOW_THREADS
    }
    free(lo);
    free(hi);
    Py_DECREF(poses);
    Py_XDECREF((PyObject *)mask);
    if (failed) {
        free(rows);
        free(ks);
        Py_XDECREF((PyObject *)gp);
        return PyErr_Occurred() ? NULL : PyErr_NoMemory();
    }
    npy_intp kd[1] = {nk};
    PyArrayObject *ra = (PyArrayObject *)PyArray_SimpleNew(1, kd, NPY_INT64);
    PyArrayObject *ka = (PyArrayObject *)PyArray_SimpleNew(1, kd, NPY_INT64);
    if (ra == NULL || ka == NULL) {
        free(rows);
        free(ks);
        Py_XDECREF((PyObject *)ra);
        Py_XDECREF((PyObject *)ka);
        Py_DECREF(gp);
        return NULL;
    }
    if (nk > 0) {
        memcpy(PyArray_DATA(ra), rows, sizeof(int64_t) * (size_t)nk);
        memcpy(PyArray_DATA(ka), ks, sizeof(int64_t) * (size_t)nk);
    }
    free(rows);
    free(ks);
    return Py_BuildValue("NNN", ra, ka, gp);
}

/* ---------------------------------------------------------------------------------- module */

static PyMethodDef methods[] = {
    {"tree", py_tree, METH_VARARGS, "Compile a tree program (see robotspec.model.program)."},
    {"fk", (PyCFunction)(void (*)(void))py_fk, METH_FASTCALL,
     "Every output pose (B, 4, 4) of one configuration."},
    {"fk_batch", py_fk_batch, METH_VARARGS, "Every output pose (N, B, 4, 4) of a batch."},
    {"tree_size", py_tree_size, METH_VARARGS, "(bodies, degrees of freedom) of a tree program."},
    {"chain", py_chain, METH_VARARGS, "Compile a chain program."},
    {"chain_fk", (PyCFunction)(void (*)(void))py_chain_fk, METH_FASTCALL,
     "root_T_tip (4, 4) of one configuration."},
    {"chain_fk_batch", py_chain_fk_batch, METH_VARARGS, "root_T_tip (N, 4, 4) of a batch."},
    {"chain_jacobian", (PyCFunction)(void (*)(void))py_chain_jacobian, METH_FASTCALL,
     "The chain's Jacobian (6, n)."},
    {"geoms", py_geoms, METH_VARARGS, "Compile the geometries and pairs of a checker."},
    {"broad", py_broad, METH_VARARGS, "Candidate (sample, pair)s and geometry poses."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_kincore",
    "Forward kinematics, chain Jacobians and the collision broad phase, in C.", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__kincore(void) {
    import_array();
    PyObject *m = PyModule_Create(&module);
    if (m != NULL && PyModule_AddIntConstant(m, "INTERFACE", KINCORE_INTERFACE) != 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
