"""Generate golden reference data (JSON) for the scanfit B-spline SURFACE tests.

Re-run from the repository root (/work/main) with:

    python3 crates/scanfit/tests/data/golden/make_surface_golden.py

Requires: pip install scipy numpy (versions recorded under "generator").
Output is deterministic; the JSON files are written next to this script:

* surface_lsq_scattered.json   bicubic LSQ fit of 2000 scattered points
                               (scipy LSQBivariateSpline, one fit per coordinate)
* surface_lsq_degree_2x3.json  degree (2,3) LSQ fit of 1500 scattered points
* surface_grid_interp.json     NURBS Book global surface interpolation
                               (sec. 9.2.5, Algorithm A9.4), bicubic, 7x6 grid

Coefficient layout in every file: "coefficients" is a flat list of [x,y,z]
control points P_ij in row-major order, u index i slowest:
coefficients[i*count_v + j] = P_ij,  S(u,v) = sum_ij N_i,p(u) M_j,q(v) P_ij.
"""
import json
import math
import os
import warnings

import numpy as np
import scipy
from scipy.interpolate import (BSpline, LSQBivariateSpline, bisplev,
                               make_interp_spline)

HERE = os.path.dirname(os.path.abspath(__file__))
GENERATOR = {
    "scipy": scipy.__version__,
    "numpy": np.__version__,
    "command": "python3 crates/scanfit/tests/data/golden/make_surface_golden.py",
}
NSAMPLES = 50
SAMPLE_SEED = 8
WRITTEN = []


# ---------------------------------------------------------------- helpers
def tolist(a):
    return np.asarray(a, dtype=float).tolist()


def write(name, obj):
    obj = {"case": name[:-5], **obj, "generator": GENERATOR}
    path = os.path.join(HERE, name)
    with open(path, "w") as f:
        json.dump(obj, f, indent=1)
        f.write("\n")
    WRITTEN.append(name)


def design(x, t, k):
    """Dense B-spline collocation matrix N[a, i] = N_i,k(x_a)."""
    return BSpline.design_matrix(np.asarray(x, float), t, k).toarray()


def tensor_eval(u, v, tu, tv, ku, kv, P):
    """Pointwise S(u_a, v_a) = sum_ij N_i(u_a) M_j(v_a) P[i, j, :]."""
    N = design(u, tu, ku)          # (m, nu)
    M = design(v, tv, kv)          # (m, nv)
    return np.einsum("ai,aj,ijd->ad", N, M, P)


def sample_params():
    rng = np.random.default_rng(SAMPLE_SEED)
    return rng.uniform(0.0, 1.0, size=(NSAMPLES, 2))


# ---------------------------------------------------------------- LSQ cases
def lsq_fit(coord, u, v, tx, ty, kx, ky):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # rank deficiency etc. must not happen
        return LSQBivariateSpline(u, v, coord, tx, ty, kx=kx, ky=ky,
                                  bbox=[0.0, 1.0, 0.0, 1.0])


def lsq_case(name, seed, npts, kx, ky, tx, ty, zfun, noise_sigma, zdesc):
    rng = np.random.default_rng(seed)
    u = rng.uniform(0.0, 1.0, size=npts)
    v = rng.uniform(0.0, 1.0, size=npts)
    x = 10.0 * u + 3.0
    y = 20.0 * v - 5.0
    z = zfun(u, v)
    if noise_sigma:
        z = z + noise_sigma * rng.standard_normal(npts)
    pts = np.column_stack([x, y, z])

    spl = [lsq_fit(pts[:, d], u, v, tx, ty, kx, ky) for d in range(3)]
    tu, tv = spl[2].get_knots()
    for s in spl:
        assert np.array_equal(s.get_knots()[0], tu)
        assert np.array_equal(s.get_knots()[1], tv)
    nu, nv = len(tu) - kx - 1, len(tv) - ky - 1
    assert nu == len(tx) + kx + 1 and nv == len(ty) + ky + 1
    assert np.all(tu[:kx + 1] == 0.0) and np.all(tu[-kx - 1:] == 1.0)
    assert np.all(tv[:ky + 1] == 0.0) and np.all(tv[-ky - 1:] == 1.0)
    C = np.stack([s.get_coeffs() for s in spl], axis=1)   # (nu*nv, 3)
    assert C.shape == (nu * nv, 3)
    P = C.reshape(nu, nv, 3)                               # y (v) index fastest

    # --- layout verification -------------------------------------------
    su = sample_params()
    ref = np.column_stack([s.ev(su[:, 0], su[:, 1]) for s in spl])
    # (a) own tensor-product evaluation with P[i, j] = coeffs[i*nv + j]
    own = tensor_eval(su[:, 0], su[:, 1], tu, tv, kx, ky, P)
    err_own = float(np.max(np.abs(own - ref)))
    # the transposed interpretation must NOT match (guards a vacuous test)
    Pt = C.reshape(nv, nu, 3).transpose(1, 0, 2)
    err_t = float(np.max(np.abs(tensor_eval(su[:, 0], su[:, 1], tu, tv,
                                            kx, ky, Pt) - ref)))
    # (b) scipy bisplev on the raw tck
    bis = np.column_stack([
        [bisplev(a, b, (tu, tv, spl[d].get_coeffs(), kx, ky)) for a, b in su]
        for d in range(3)])
    err_bis = float(np.max(np.abs(bis - ref)))
    assert err_own < 1e-12 and err_bis < 1e-12 and err_t > 1e-3, \
        (err_own, err_bis, err_t)

    # --- independent LSQ check: dense Kronecker least squares -----------
    N = design(u, tu, kx)
    M = design(v, tv, ky)
    A = (N[:, :, None] * M[:, None, :]).reshape(npts, nu * nv)
    sv = np.linalg.svd(A, compute_uv=False)
    cond = float(sv[0] / sv[-1])
    assert sv[-1] > 1e-8 * sv[0], "design matrix rank deficient"
    Cd = np.linalg.lstsq(A, pts, rcond=None)[0]
    err_dense = float(np.max(np.abs(Cd - C)))
    assert err_dense < 1e-9, err_dense
    resid = A @ C - pts
    ssr = (resid ** 2).sum(axis=0)
    fp = float(spl[2].get_residual())
    assert abs(fp - ssr[2]) <= 1e-9 * max(1.0, ssr[2]), (fp, ssr[2])
    # x, y are linear in u, v: the fit is exact and the control points are
    # the Greville abscissae mapped through the linear maps
    gu = np.array([tu[i + 1:i + kx + 1].mean() for i in range(nu)])
    gv = np.array([tv[j + 1:j + ky + 1].mean() for j in range(nv)])
    err_lin = max(float(np.max(np.abs(P[:, :, 0] - (10 * gu[:, None] + 3)))),
                  float(np.max(np.abs(P[:, :, 1] - (20 * gv[None, :] - 5)))))
    assert err_lin < 1e-9, err_lin
    fit_pts = np.column_stack([s.ev(u, v) for s in spl])
    rms = np.sqrt(np.mean((fit_pts - pts) ** 2, axis=0))

    write(name, {
        "description": (
            f"Least-squares tensor-product B-spline surface fit, degrees "
            f"({kx},{ky}), {npts} scattered points. x = 10*u + 3, "
            f"y = 20*v - 5, z = {zdesc}. Each coordinate fitted separately "
            f"with scipy.interpolate.LSQBivariateSpline(u, v, coord, tx, ty, "
            f"kx={kx}, ky={ky}, bbox=[0,1,0,1]) on the given params."),
        "data_generation": (
            f"rng = numpy.random.default_rng({seed}); "
            f"u = rng.uniform(0,1,size={npts}); v = rng.uniform(0,1,size={npts})"
            + (f"; noise = {noise_sigma}*rng.standard_normal({npts})"
               if noise_sigma else "")
            + " (drawn in exactly this order)."),
        "seed": seed,
        "sample_seed": SAMPLE_SEED,
        "degree_u": kx,
        "degree_v": ky,
        "interior_knots_u": list(map(float, tx)),
        "interior_knots_v": list(map(float, ty)),
        "knots_u": tolist(tu),
        "knots_v": tolist(tv),
        "count_u": nu,
        "count_v": nv,
        "params": tolist(np.column_stack([u, v])),
        "points": tolist(pts),
        "coefficients": tolist(C),
        "coefficients_layout": "row-major, u index i slowest: "
                               "coefficients[i*count_v + j] = P_ij = [x,y,z]",
        "note": (
            "scipy get_coeffs() has length (nx-kx-1)*(ny-ky-1) with the y (v) "
            "index fastest, i.e. it already is row-major with u slowest; it is "
            "written unchanged. Verified at the 50 sample params: an "
            "independent tensor-product evaluation sum_ij N_i(u) M_j(v) "
            "c[i*count_v+j] (BSpline.design_matrix) matches spline.ev to "
            f"{err_own:.1e}; scipy.interpolate.bisplev((knots_u, knots_v, c, "
            f"kx, ky)) matches to {err_bis:.1e}; the transposed reading "
            f"c[j*count_u+i] differs by {err_t:.2e} (so the check is not "
            "vacuous). Coefficients also agree with a dense numpy lstsq on "
            f"the Kronecker collocation matrix to {err_dense:.1e} "
            f"(matrix full rank, 2-norm condition number {cond:.3e}). x/y "
            "control points equal 10*greville_u+3 / 20*greville_v-5 to "
            f"{err_lin:.1e}. No warnings were raised by LSQBivariateSpline "
            "(warnings turned into errors)."),
        "fp": fp,
        "fp_definition": "spline_z.get_residual() = sum_k (S_z(u_k,v_k) - z_k)^2",
        "residual_sum_squares_xyz": tolist(ssr),
        "rms_error_xyz": tolist(rms),
        "samples": {"uv": tolist(su), "values": tolist(ref)},
    })
    return fp, err_own, err_bis, err_t, err_dense, cond


# ---------------------------------------------------------------- grid interp
def chord_params(pts):
    """NURBS Book eq. 9.5: chord length params, sequential sums, u_n = 1."""
    d = np.sqrt(((pts[1:] - pts[:-1]) ** 2).sum(axis=1))
    total = d.sum()
    assert total > 0
    u = np.empty(len(pts))
    u[0] = 0.0
    acc = 0.0
    for i in range(1, len(pts) - 1):
        acc += d[i - 1]
        u[i] = acc / total
    u[-1] = 1.0
    return u


def averaging_knots(u, p):
    """NURBS Book eq. 9.8."""
    n = len(u) - 1
    inner = [sum(u[j:j + p]) / p for j in range(1, n - p + 1)]
    return np.array([0.0] * (p + 1) + inner + [1.0] * (p + 1))


def grid_case():
    p = q = 3
    r, s = 6, 5
    Q = np.empty((r + 1, s + 1, 3))
    for k in range(r + 1):
        for l in range(s + 1):
            Q[k, l] = [k + 0.1 * l, l * 1.3 + 0.05 * k * k,
                       math.sin(k * 0.7) + math.cos(l * 0.9)]
    # parameters (A9.4): average of per-row / per-column chord params
    uk = np.mean([chord_params(Q[:, l]) for l in range(s + 1)], axis=0)
    vl = np.mean([chord_params(Q[k, :]) for k in range(r + 1)], axis=0)
    assert uk[0] == 0.0 and uk[-1] == 1.0 and vl[0] == 0.0 and vl[-1] == 1.0
    U = averaging_knots(uk, p)
    V = averaging_knots(vl, q)
    assert len(U) == r + p + 2 and len(V) == s + q + 2
    # step 1: for each l, interpolate Q_{0l}..Q_{rl} at u_k -> R_{il}
    R = np.empty((r + 1, s + 1, 3))
    for l in range(s + 1):
        b = make_interp_spline(uk, Q[:, l], k=p, t=U)
        R[:, l] = b.c
    # step 2: for each i, interpolate R_{i0}..R_{is} at v_l -> P_ij
    P = np.empty((r + 1, s + 1, 3))
    for i in range(r + 1):
        b = make_interp_spline(vl, R[i, :], k=q, t=V)
        P[i, :] = b.c
    # verification: S(u_k, v_l) = N P M^T reproduces every Q_kl
    N = design(uk, U, p)
    M = design(vl, V, q)
    S = np.einsum("ki,lj,ijd->kld", N, M, P)
    err = float(np.max(np.abs(S - Q)))
    assert err < 1e-12, err
    su = sample_params()
    vals = tensor_eval(su[:, 0], su[:, 1], U, V, p, q, P)
    # cross-check samples against scipy bisplev per coordinate
    for d in range(3):
        bv = [bisplev(a, b, (U, V, P[:, :, d].ravel(), p, q)) for a, b in su]
        assert np.max(np.abs(np.array(bv) - vals[:, d])) < 1e-12
    write("surface_grid_interp.json", {
        "description": (
            "Global bicubic surface interpolation, NURBS Book (Piegl & Tiller) "
            "sec. 9.2.5 / Algorithm A9.4, on a (r+1)x(s+1) = 7x6 grid "
            "Q_kl = (k + 0.1*l, 1.3*l + 0.05*k^2, sin(0.7*k) + cos(0.9*l)), "
            "k = 0..6, l = 0..5."),
        "method": (
            "params_u: for each l, chord-length params (eq. 9.5, sequential "
            "sums, first 0, last exactly 1) of Q_0l..Q_rl; params_u = mean "
            "over l. params_v analogously over k. Knots by averaging "
            "(eq. 9.8). Step 1: for each l, make_interp_spline(params_u, "
            "Q_{.l}, k=3, t=knots_u).c -> R_il. Step 2: for each i, "
            "make_interp_spline(params_v, R_{i.}, k=3, t=knots_v).c -> P_ij."),
        "degree_u": p,
        "degree_v": q,
        "count_u": r + 1,
        "count_v": s + 1,
        "params_u": tolist(uk),
        "params_v": tolist(vl),
        "knots_u": tolist(U),
        "knots_v": tolist(V),
        "grid": tolist(Q),
        "grid_layout": "grid[k][l] = Q_kl = [x,y,z], k (u direction) outer",
        "coefficients": tolist(P.reshape(-1, 3)),
        "coefficients_layout": "row-major, u index i slowest: "
                               "coefficients[i*count_v + j] = P_ij = [x,y,z]",
        "interpolation_max_error": err,
        "note": (
            "Verified: S(u_k, v_l) = sum_ij N_i(u_k) M_j(v_l) P_ij "
            "(BSpline.design_matrix) reproduces every Q_kl to "
            f"{err:.1e} (asserted < 1e-12). Samples evaluated with the same "
            "tensor-product evaluation and cross-checked against "
            "scipy.interpolate.bisplev."),
        "sample_seed": SAMPLE_SEED,
        "samples": {"uv": tolist(su), "values": tolist(vals)},
    })
    return err


def main():
    r1 = lsq_case(
        "surface_lsq_scattered.json", seed=7, npts=2000, kx=3, ky=3,
        tx=[0.2, 0.4, 0.6, 0.8], ty=[0.25, 0.5, 0.75],
        zfun=lambda u, v: np.sin(3 * u) * np.cos(2 * v) + 0.3 * u * v ** 2,
        noise_sigma=0.01,
        zdesc="sin(3u)*cos(2v) + 0.3*u*v^2 + noise")
    r2 = lsq_case(
        "surface_lsq_degree_2x3.json", seed=9, npts=1500, kx=2, ky=3,
        tx=[0.3, 0.5, 0.7], ty=[0.2, 0.6],
        zfun=lambda u, v: np.exp(-((u - 0.5) ** 2 + (v - 0.4) ** 2) * 4),
        noise_sigma=0.0,
        zdesc="exp(-4*((u-0.5)^2 + (v-0.4)^2)) (no noise)")
    e3 = grid_case()
    for name, r in (("scattered", r1), ("2x3", r2)):
        print(f"{name}: fp={r[0]:.6e} err_own={r[1]:.1e} err_bisplev={r[2]:.1e} "
              f"err_transposed={r[3]:.2e} err_dense={r[4]:.1e} cond={r[5]:.3e}")
    print(f"grid interp max error {e3:.1e}")
    print("wrote:", ", ".join(WRITTEN))


if __name__ == "__main__":
    main()
