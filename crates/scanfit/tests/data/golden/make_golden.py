"""Generate golden reference data (JSON) for the scanfit B-spline tests using SciPy.

Re-run from the repository root (/work/main) with:

    python3 crates/scanfit/tests/data/golden/make_golden.py

Requires: pip install scipy numpy  (versions are recorded in every JSON file
under "generator").  Output is deterministic; all JSON files are written next
to this script.  Input data: /work/shared/data/curves/dataset{1..6}.csv
(override the directory with env var SCANFIT_CURVES_DIR).

Conventions
-----------
* chord params:       d_i = sqrt(dx^2+dy^2+dz^2) of P_i - P_{i-1}; u_0 = 0,
                      u_k = (d_1+...+d_k) / (d_1+...+d_n) (sequential sums),
                      u_n = 1.0 exactly.
* centripetal params: same with sqrt(d_i).
* interpolation knots: averaging (NURBS Book eq. 9.8).
* end-derivative interpolation (cubic): knots [0]*4 + u_1..u_{n-1} + [1]*4.
* least squares knots: NURBS Book eq. 9.68-9.69.
* samples: 50 parameters np.linspace(t[p], t[len(t)-p-1], 50) (curve domain).
"""
import csv
import json
import math
import os
import sys

import numpy as np
import scipy
from scipy.interpolate import (BSpline, make_interp_spline, make_lsq_spline,
                               make_smoothing_spline)

HERE = os.path.dirname(os.path.abspath(__file__))
DATA_DIR = os.environ.get("SCANFIT_CURVES_DIR", "/work/shared/data/curves")
GENERATOR = {
    "scipy": scipy.__version__,
    "numpy": np.__version__,
    "command": "python3 crates/scanfit/tests/data/golden/make_golden.py",
}
NSAMPLES = 50
WRITTEN = []


# ---------------------------------------------------------------- helpers
def read_points(k):
    path = os.path.join(DATA_DIR, f"dataset{k}.csv")
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    assert [h.strip() for h in rows[0]] == ["x", "y", "z"], rows[0]
    pts = [[float(v) for v in r] for r in rows[1:] if r]
    assert all(len(p) == 3 for p in pts)
    return pts


def params(points, method):
    d = []
    for a, b in zip(points[:-1], points[1:]):
        dx, dy, dz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
        di = math.sqrt(dx * dx + dy * dy + dz * dz)
        if method == "centripetal":
            di = math.sqrt(di)
        elif method != "chord":
            raise ValueError(method)
        d.append(di)
    total = 0.0
    for di in d:
        total += di
    assert total > 0.0
    u = [0.0]
    acc = 0.0
    for di in d[:-1]:
        acc += di
        u.append(acc / total)
    u.append(1.0)
    assert all(b > a for a, b in zip(u[:-1], u[1:])), "repeated points"
    return u


def averaging_knots(u, p):
    n = len(u) - 1
    t = [0.0] * (p + 1)
    for j in range(1, n - p + 1):
        s = 0.0
        for i in range(j, j + p):
            s += u[i]
        t.append(s / p)
    t += [1.0] * (p + 1)
    assert len(t) == n + p + 2
    return t


def lsq_knots(u, n_ctrl, p):
    m = len(u) - 1
    n = n_ctrl - 1
    d = (m + 1) / (n - p + 1)
    t = [0.0] * (p + 1)
    for j in range(1, n - p + 1):
        i = int(math.floor(j * d))
        alpha = j * d - i
        t.append((1.0 - alpha) * u[i - 1] + alpha * u[i])
    t += [1.0] * (p + 1)
    assert len(t) == n_ctrl + p + 1
    return t


def fl(a):
    """numpy array -> nested lists of Python floats."""
    return np.asarray(a, dtype=float).tolist()


def samples(spl, p):
    t = spl.t
    us = np.linspace(t[p], t[len(t) - p - 1], NSAMPLES)
    vals = spl(us)
    return {"u": fl(us), "values": fl(vals)}


def write(name, obj):
    obj = {"case": name[:-5], **obj, "generator": GENERATOR}
    path = os.path.join(HERE, name)
    with open(path, "w") as f:
        json.dump(obj, f, indent=1)
        f.write("\n")
    WRITTEN.append(path)


def check_interp(spl, u, P, tol=1e-9):
    err = np.max(np.abs(spl(np.asarray(u)) - np.asarray(P)))
    scale = max(1.0, np.max(np.abs(P)))
    assert err <= tol * scale, f"interp error {err}"
    return float(err)


# ---------------------------------------------------------------- 1. interp
def case_interp():
    for k in range(1, 7):
        P = read_points(k)
        degrees = [2, 3] + ([5] if k == 6 else [])
        for p in degrees:
            for method in ("chord", "centripetal"):
                u = params(P, method)
                t = averaging_knots(u, p)
                spl = make_interp_spline(np.array(u), np.array(P), k=p,
                                         t=np.array(t))
                assert np.array_equal(spl.t, np.array(t))
                check_interp(spl, u, P)
                write(f"interp_ds{k}_p{p}_{method}.json", {
                    "dataset": k, "param_method": method,
                    "degree": p, "points": P, "params": u, "knots": t,
                    "coefficients": fl(spl.c), "samples": samples(spl, p),
                })


# ------------------------------------------------- 2. interp with end derivs
def case_interp_derivs():
    P = read_points(1)
    u = params(P, "chord")
    n = len(P) - 1
    p = 3
    D0 = [1.0, -0.5, 0.0]
    Dn = [2.0, 1.0, 0.0]
    t = [0.0] * 4 + u[1:n] + [1.0] * 4
    assert len(t) == (n + 3) + 4
    spl = make_interp_spline(np.array(u), np.array(P), k=3,
                             bc_type=([(1, D0)], [(1, Dn)]), t=np.array(t))
    assert np.array_equal(spl.t, np.array(t))
    assert spl.c.shape == (n + 3, 3)
    check_interp(spl, u, P)
    der = spl.derivative(1)
    assert np.allclose(der(0.0), D0, atol=1e-9) and np.allclose(der(1.0), Dn, atol=1e-9)
    write("interp_ds1_p3_chord_derivs.json", {
        "dataset": 1, "param_method": "chord",
        "degree": p, "points": P, "params": u, "knots": t,
        "d0": D0, "dn": Dn,
        "coefficients": fl(spl.c), "samples": samples(spl, p),
        "note": "knots = [0]*4 + params[1:n] + [1]*4 (NURBS Book sec. 9.2.4 "
                "cubic with end derivatives); n+3 control points; accepted by "
                "scipy make_interp_spline(bc_type=([(1,d0)],[(1,dn)]), t=knots).",
    })


# ------------------------------------------------------- 3./4. least squares
def case_lsq():
    P = read_points(6)
    Pa = np.array(P)
    u = params(P, "chord")
    ua = np.array(u)
    p = 3
    for N in (10, 20):
        t = lsq_knots(u, N, p)
        ta = np.array(t)
        spl = make_lsq_spline(ua, Pa, ta, k=p)
        assert spl.c.shape == (N, 3)
        write(f"lsq_free_ds6_p3_n{N}.json", {
            "dataset": 6, "param_method": "chord",
            "degree": p, "ctrl_count": N, "points": P, "params": u, "knots": t,
            "coefficients": fl(spl.c), "samples": samples(spl, p),
        })

        A = BSpline.design_matrix(ua, ta, p).toarray()
        assert A.shape == (len(u), N)
        P0, Pn = Pa[0], Pa[-1]
        rhs = Pa - np.outer(A[:, 0], P0) - np.outer(A[:, N - 1], Pn)
        inner, *_ = np.linalg.lstsq(A[:, 1:N - 1], rhs, rcond=None)
        coef = np.vstack([P0, inner, Pn])
        spl_f = BSpline(ta, coef, p)
        # clamped knots => curve passes exactly through P0, Pn
        assert np.allclose(spl_f(0.0), P0) and np.allclose(spl_f(1.0), Pn)
        write(f"lsq_fixed_ds6_p3_n{N}.json", {
            "dataset": 6, "param_method": "chord",
            "degree": p, "ctrl_count": N, "points": P, "params": u, "knots": t,
            "coefficients": fl(coef), "samples": samples(spl_f, p),
            "note": "first/last control points fixed to first/last data point; "
                    "remaining unknowns from numpy.linalg.lstsq on dense "
                    "BSpline.design_matrix with fixed columns moved to rhs.",
        })


# ------------------------------------------------------------- 5. smoothing
def gram_second_derivative(t, k=3):
    """G_ij = integral B_i''(u) B_j''(u) du, exact via 2-pt Gauss per span."""
    nc = len(t) - k - 1
    basis2 = BSpline(t, np.eye(nc), k).derivative(2)
    g, w = np.polynomial.legendre.leggauss(2)
    G = np.zeros((nc, nc))
    for a, b in zip(t[:-1], t[1:]):
        if b <= a:
            continue
        xq = 0.5 * (b - a) * g + 0.5 * (a + b)
        B = basis2(xq)  # (nq, nc)
        G += (B.T * (0.5 * (b - a) * w)) @ B
    return G


def case_smoothing():
    lams = [("1e-3", 1e-3), ("1e-1", 1e-1), ("10.0", 10.0)]
    for k in (6, 1):
        P = read_points(k)
        Pa = np.array(P)
        u = params(P, "chord")
        ua = np.array(u)
        for tag, lam in lams:
            spls = [make_smoothing_spline(ua, Pa[:, c], lam=lam) for c in range(3)]
            t = spls[0].t
            for s in spls[1:]:
                assert np.array_equal(s.t, t), "per-coordinate knots differ"
                assert s.k == 3
            coef = np.column_stack([s.c for s in spls])
            spl = BSpline(t, coef, 3)
            # independent check of the objective:
            #   sum_i (y_i - f(u_i))^2 + lam * int_{u_0}^{u_m} f''(u)^2 du
            A = BSpline.design_matrix(ua, t, 3).toarray()
            G = gram_second_derivative(t)
            ref = np.linalg.solve(A.T @ A + lam * G, A.T @ Pa)
            relerr = float(np.max(np.abs(ref - coef)) / np.max(np.abs(coef)))
            assert relerr < 1e-7, relerr  # normal equations limit accuracy
            # a wrong scaling (e.g. lam/m or 6*lam) would differ by >> 1e-8
            alt = np.linalg.solve(A.T @ A + 6 * lam * G, A.T @ Pa)
            assert np.max(np.abs(alt - coef)) / np.max(np.abs(coef)) > 1e-6

            def J(c):
                r = Pa - A @ c
                return float(np.sum(r * r) + lam * np.trace(c.T @ G @ c))
            write(f"smooth_ds{k}_lam{tag}.json", {
                "dataset": k, "param_method": "chord",
                "degree": 3, "lam": lam, "points": P, "params": u,
                "knots": fl(t), "coefficients": fl(coef),
                "samples": samples(spl, 3),
                "objective": "sum_i 1.0*|P_i - C(u_i)|^2 + lam * integral_{u_0}^{u_m} "
                             "|C''(u)|^2 du  (weights w_i = 1, not squared; "
                             "per coordinate, summed over x,y,z; no 1/m or 1/2 factors)",
                "objective_value": J(coef),
                "note": (
                    "scipy make_smoothing_spline(u, P[:,c], lam=lam) per coordinate; "
                    "knots t = [u_0]*3 + u + [u_m]*3 (all params as knots, 4-fold "
                    "clamped ends), m+3 coefficients, natural cubic spline "
                    "(C''=0 at ends); identical t for x,y,z (asserted). Source "
                    "(scipy/interpolate/_bsplines.py) solves (X + lam*W^-1 E) c = y "
                    "in a natural-spline basis with E = 6*divided-difference "
                    "penalty, i.e. lam multiplies the integral directly (Reinsch "
                    "form). Verified independently: solving (A^T A + lam*G) c = A^T P "
                    "with A = design matrix, G_ij = int B_i'' B_j'' (exact Gauss) "
                    f"reproduces scipy's coefficients to rel. err {relerr:.1e}; "
                    "6*lam does not."),
            })


# -------------------------------------------------------------- 6. periodic
def case_periodic():
    P = read_points(1)
    Pc = P + [list(P[0])]
    assert len(Pc) == 11 and Pc[-1] == Pc[0]
    u = params(Pc, "chord")
    for p in (3, 2):
        try:
            spl = make_interp_spline(np.array(u), np.array(Pc), k=p,
                                     bc_type="periodic")
        except Exception as e:  # pragma: no cover
            print(f"periodic p={p} not supported: {e!r}", file=sys.stderr)
            continue
        check_interp(spl, u, Pc)
        d1 = spl.derivative(1)
        assert np.allclose(d1(0.0), d1(1.0))
        nc = len(spl.t) - p - 1
        assert spl.c.shape == (nc, 3)
        assert np.allclose(spl.c[:p], spl.c[nc - p:])
        note = ("closed loop: dataset1 points P_0..P_9 + P_0 appended (11 values); "
                "chord params over closed polygon incl. closing segment; "
                f"make_interp_spline(u, Pclosed, k={p}, bc_type='periodic'). "
                "Knots are scipy's _periodic_knots: len = 11 + 2k, "
                "t[k:k+11] = ")
        if p % 2 == 1:
            note += "params, "
        else:
            note += ("[u_0, midpoints (u_{i-1}+u_i)/2 for i=1..9, u_10] "
                     "(even degree shifts interior knots to midpoints), ")
        note += (f"outer {p} knots on each side continue the spacing periodically "
                 f"(period 1). Coefficients: len(t)-k-1 = {nc}; the last {p} "
                 f"equal the first {p} (wrapped). Domain [t[k], t[-k-1]] = [0, 1]; "
                 "scipy spline has extrapolate='periodic'.")
        write(f"periodic_ds1_p{p}_chord.json", {
            "dataset": 1, "param_method": "chord",
            "degree": p, "points": Pc, "params": u, "knots": fl(spl.t),
            "coefficients": fl(spl.c), "samples": samples(spl, p),
            "note": note,
        })


def main():
    case_interp()
    case_interp_derivs()
    case_lsq()
    case_smoothing()
    case_periodic()
    total = 0
    for path in WRITTEN:
        with open(path) as f:
            json.load(f)
        sz = os.path.getsize(path)
        total += sz
        print(f"{sz:8d}  {os.path.basename(path)}")
    print(f"{len(WRITTEN)} files, {total} bytes; scipy {scipy.__version__}, "
          f"numpy {np.__version__}")


if __name__ == "__main__":
    main()
