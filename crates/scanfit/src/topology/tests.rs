use super::volume::gauss_legendre;
use super::*;
use crate::bspline::{KnotVector, Surface};

fn lin() -> KnotVector {
    KnotVector::uniform_clamped(1, 2).unwrap()
}

/// A bilinear face through four corners given counter-clockwise (seen from
/// the side its normal points to).
fn quad(c: [Point3; 4]) -> Surface {
    Surface::new(lin(), lin(), vec![c[0], c[3], c[1], c[2]]).unwrap()
}

/// The cube [0, s]^3, normals outwards; vertex index = x + 2y + 4z.
fn cube(s: f64) -> PatchComplex {
    let v: Vec<Point3> = (0..8)
        .map(|i| {
            Point3::new(
                (i & 1) as f64 * s,
                ((i >> 1) & 1) as f64 * s,
                ((i >> 2) & 1) as f64 * s,
            )
        })
        .collect();
    let faces = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let fc = faces
        .iter()
        .enumerate()
        .map(|(i, c)| FaceCorners {
            id: 10 + i as i64,
            surface: quad(c.map(|k| v[k])),
            corners: *c,
        })
        .collect();
    PatchComplex::assemble(v, fc).unwrap()
}

#[test]
fn cube_of_six_bilinear_faces_is_closed_and_valid() {
    let m = cube(1.0);
    assert_eq!((m.vertices.len(), m.edges.len(), m.faces.len()), (8, 12, 6));
    m.validate().unwrap();
    assert!(m.is_closed());
    assert!(m.border_edges().is_empty());
    let users = m.edge_faces();
    assert!(users
        .iter()
        .all(|u| u.len() == 2 && u[0].reversed != u[1].reversed));
    let gaps = m.boundary_gaps().unwrap();
    assert_eq!(gaps.len(), 12);
    assert!(m.max_boundary_gap().unwrap() < 1e-14);
    assert!(
        (m.signed_volume() - 1.0).abs() < 1e-13,
        "{}",
        m.signed_volume()
    );
    assert!((m.scale() - 3f64.sqrt()).abs() < 1e-15);
    assert_eq!(m.face_vertices(0).unwrap(), vec![0, 2, 3, 1]);
}

#[test]
fn moved_side_is_reported_with_its_gap() {
    for s in [1.0, 1000.0] {
        let mut m = cube(s);
        // move side 0 of face 0 (control points P_00 and P_10) by d along -z
        let d = 0.01 * s;
        let f = &m.faces[0].surface;
        let mut ctrl = f.control_points().to_vec();
        ctrl[0].z -= d;
        ctrl[2].z -= d;
        m.faces[0].surface = Surface::new(lin(), lin(), ctrl).unwrap();
        let gaps = m.boundary_gaps().unwrap();
        let e0 = m.faces[0].sides[0][0].edge;
        let g = &gaps[e0];
        assert!((g.curve_gap - d).abs() < 1e-9 * s, "{}", g.curve_gap);
        assert!((g.face_gap - d).abs() < 1e-9 * s, "{}", g.face_gap);
        assert_eq!(g.worst_side.unwrap().face, 0);
        assert!((m.max_boundary_gap().unwrap() - d).abs() < 1e-9 * s);
        let err = m.validate().unwrap_err().to_string();
        assert!(err.contains("face 0 (patch 10) side"), "{err}");
        assert!(err.contains("away from edge"), "{err}");
        // the same model passes with a tolerance above the gap (relative to size)
        m.validate_with(0.01).unwrap();
        // and a move below the default relative tolerance is accepted
        let mut m2 = cube(s);
        let mut ctrl = m2.faces[0].surface.control_points().to_vec();
        ctrl[0].z -= 1e-9 * s;
        m2.faces[0].surface = Surface::new(lin(), lin(), ctrl).unwrap();
        m2.validate().unwrap();
        let g2 = m2.max_boundary_gap().unwrap();
        assert!(g2 > 0.5e-9 * s && g2 < 1.5e-9 * s, "{g2}");
    }
}

#[test]
fn flipped_face_is_an_orientation_error() {
    let mut m = cube(1.0);
    // reparameterize face 2 with u and v swapped: its normal now points inwards
    let c = [0usize, 4, 5, 1].map(|k| m.vertices[k].point);
    let v: Vec<Point3> = m.vertices.iter().map(|v| v.point).collect();
    let mut fc: Vec<FaceCorners> = m
        .faces
        .iter()
        .enumerate()
        .map(|(i, f)| FaceCorners {
            id: f.id,
            surface: f.surface.clone(),
            corners: m.face_vertices(i).unwrap().try_into().unwrap(),
        })
        .collect();
    fc[2] = FaceCorners {
        id: 12,
        surface: quad(c),
        corners: [0, 4, 5, 1],
    };
    m = PatchComplex::assemble(v, fc).unwrap();
    let err = m.validate().unwrap_err().to_string();
    assert!(err.contains("same direction by faces"), "{err}");
}

#[test]
fn structural_errors_name_what_is_wrong() {
    let m = cube(1.0);
    let mut bad = m.clone();
    bad.faces[3].sides[1] = vec![EdgeUse {
        edge: 99,
        reversed: false,
    }];
    let err = bad.validate().unwrap_err().to_string();
    assert!(
        err.contains("face 3 (patch 13) side 1 uses edge 99"),
        "{err}"
    );

    let mut bad = m.clone();
    let u = bad.faces[1].sides[2][0];
    bad.faces[1].sides[2] = vec![EdgeUse {
        reversed: !u.reversed,
        ..u
    }];
    let err = bad.validate().unwrap_err().to_string();
    assert!(err.contains("closed cycle"), "{err}");

    let mut bad = m.clone();
    bad.faces.push(bad.faces[0].clone());
    let err = bad.validate().unwrap_err().to_string();
    assert!(err.contains("used by 3 face sides"), "{err}");

    let mut bad = m.clone();
    bad.edges[0].end = bad.edges[0].start;
    let err = bad.validate().unwrap_err().to_string();
    assert!(err.contains("edge 0 starts and ends at vertex"), "{err}");

    let mut bad = m.clone();
    bad.vertices[7].point.x += 0.1;
    let err = bad.validate().unwrap_err().to_string();
    assert!(err.contains("from vertex 7"), "{err}");

    let mut bad = m;
    bad.faces[0].sides[1].clear();
    bad.faces[0].sides[2].clear();
    let err = bad.validate().unwrap_err().to_string();
    assert!(err.contains("2 non-degenerate sides"), "{err}");

    assert!(PatchComplex::default().validate().is_err());
}

/// The tetrahedron (0,0,0), e_x, e_y, e_z as four three-sided bilinear faces
/// with side 3 collapsed (corners [a, b, c, a]).
fn tetrahedron() -> PatchComplex {
    let v = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 0.0, 0.0),
        Point3::new(0.0, 1.0, 0.0),
        Point3::new(0.0, 0.0, 1.0),
    ];
    let tris = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let fc = tris
        .iter()
        .enumerate()
        .map(|(i, t)| FaceCorners {
            id: i as i64,
            surface: quad([v[t[0]], v[t[1]], v[t[2]], v[t[0]]]),
            corners: [t[0], t[1], t[2], t[0]],
        })
        .collect();
    PatchComplex::assemble(v, fc).unwrap()
}

#[test]
fn three_sided_faces_with_a_collapsed_side() {
    let m = tetrahedron();
    assert_eq!(m.edges.len(), 6);
    m.validate().unwrap();
    assert!(m.is_closed());
    assert!(m
        .faces
        .iter()
        .all(|f| f.side_count() == 3 && f.sides[3].is_empty()));
    assert_eq!(m.degenerate_vertex(3, 3), Some(1));
    assert_eq!(m.degenerate_vertex(3, 0), None);
    assert!((m.signed_volume() - 1.0 / 6.0).abs() < 1e-14);
    // a side marked degenerate whose surface side has length is rejected
    let mut bad = m.clone();
    let c = [0, 2, 1].map(|k| m.vertices[k].point);
    bad.faces[0].surface = quad([c[0], c[1], c[2], Point3::new(0.5, 0.0, 0.0)]);
    let err = bad.validate().unwrap_err().to_string();
    assert!(err.contains("face 0"), "{err}");
}

#[test]
fn side_curves_match_the_surface_sides_for_unclamped_rational_surfaces() {
    // bicubic, uniform unclamped knots, non-unit weights
    let ku = KnotVector::new((0..9).map(|i| i as f64).collect(), 3).unwrap();
    let kv = KnotVector::new((0..10).map(|i| i as f64 * 0.5).collect(), 3).unwrap();
    let (nu, nv) = (ku.basis_count(), kv.basis_count());
    let ctrl: Vec<Point3> = (0..nu * nv)
        .map(|k| {
            let (i, j) = ((k / nv) as f64, (k % nv) as f64);
            Point3::new(i, j, (i * 0.7).sin() + (j * 1.3).cos())
        })
        .collect();
    let w: Vec<f64> = (0..nu * nv)
        .map(|k| 1.0 + 0.3 * ((k * 7) % 5) as f64)
        .collect();
    let s = Surface::with_options(ku, kv, ctrl, Some(w), false, false).unwrap();
    let f = Face {
        id: 0,
        surface: s,
        sides: Default::default(),
    };
    for k in 0..4 {
        let c = f.side_curve(k).unwrap();
        let (a, b) = c.domain();
        for i in 0..=20 {
            let s = i as f64 / 20.0;
            let d = (c.point(a + (b - a) * s) - f.side_point(k, s)).norm();
            assert!(d < 1e-12, "side {k} at {s}: {d}");
        }
    }
}

#[test]
fn reversed_curve_runs_backwards_on_the_same_domain() {
    let kv = KnotVector::new(vec![2.0, 2.0, 2.0, 3.0, 5.0, 5.0, 5.0], 2).unwrap();
    let c = Curve::new(
        kv,
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 2.0, 0.0),
            Point3::new(3.0, 1.0, 1.0),
            Point3::new(4.0, 0.0, 2.0),
        ],
    )
    .unwrap();
    let r = reversed_curve(&c).unwrap();
    assert_eq!(r.domain(), (2.0, 5.0));
    for i in 0..=10 {
        let t = 2.0 + 0.3 * i as f64;
        assert!((r.point(t) - c.point(7.0 - t)).norm() < 1e-14);
    }
}

#[test]
fn gauss_legendre_is_exact_to_degree_2n_minus_1() {
    for n in 1..=10 {
        let g = gauss_legendre(n);
        assert!((g.iter().map(|x| x.1).sum::<f64>() - 2.0).abs() < 1e-14);
        let d = 2 * n - 2; // even power: exact value 2 / (d + 1)
        let integral: f64 = g.iter().map(|&(x, w)| w * x.powi(d as i32)).sum();
        assert!((integral - 2.0 / (d as f64 + 1.0)).abs() < 1e-14, "n {n}");
    }
}

#[test]
fn volume_quadrature_is_exact_for_bicubic_faces() {
    // the cube [0,2]^3 with every face written as a bicubic B-spline with an
    // interior knot (linear precision: control points = the bilinear map at
    // the Greville abscissae), so the integrand has degree 8 per span
    let m = cube(2.0);
    let k3 = KnotVector::new(vec![0.0, 0.0, 0.0, 0.0, 0.3, 1.0, 1.0, 1.0, 1.0], 3).unwrap();
    let g = crate::base::coons::greville(&k3);
    let faces: Vec<Surface> = m
        .faces
        .iter()
        .map(|f| {
            let mut ctrl = Vec::new();
            for &u in &g {
                for &v in &g {
                    ctrl.push(f.surface.point(u, v));
                }
            }
            Surface::new(k3.clone(), k3.clone(), ctrl).unwrap()
        })
        .collect();
    let v = volume::signed_volume(&faces);
    assert!((v - 8.0).abs() < 1e-12, "{v}");
    // one curved face's flux: the biquadratic z = x^2 on [0,1]^2 (x = u,
    // y = v): ∫∫ S.(S_u x S_v)
    // = ∫∫ (u, v, u^2).(-2u, 0, 1) = ∫∫ -u^2 = -1/3, volume term -1/9
    let k2 = KnotVector::uniform_clamped(2, 3).unwrap();
    let mut ctrl = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            // control values of u^2 on [0,0,0,1,1,1]: 0, 0, 1
            let z = if i == 2 { 1.0 } else { 0.0 };
            ctrl.push(Point3::new(i as f64 / 2.0, j as f64 / 2.0, z));
        }
    }
    let s = Surface::new(k2.clone(), k2, ctrl).unwrap();
    assert!((s.point(0.3, 0.6).z - 0.09).abs() < 1e-15);
    assert!((volume::signed_volume([&s]) + 1.0 / 9.0).abs() < 1e-14);
}

#[test]
fn normal_angles_measure_the_g1_defect() {
    // the cube: every edge is a 90 degree crease
    let m = cube(2.0);
    let a = m.normal_angles(9).unwrap();
    assert_eq!(a.len(), 12);
    for x in &a {
        let x = x.unwrap();
        assert!((x - 90.0).abs() < 1e-9, "{x}");
    }
    // two squares folded by 30 degrees about their shared edge x = 1
    let fold = 30f64.to_radians();
    let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
    let q = |d: f64, y: f64| Point3::new(1.0 + d * fold.cos(), y, d * fold.sin());
    let verts = vec![
        p(0.0, 0.0),
        p(1.0, 0.0),
        q(1.0, 0.0),
        p(0.0, 1.0),
        p(1.0, 1.0),
        q(1.0, 1.0),
    ];
    let m = PatchComplex::assemble(
        verts.clone(),
        vec![
            FaceCorners {
                id: 1,
                surface: quad([verts[0], verts[1], verts[4], verts[3]]),
                corners: [0, 1, 4, 3],
            },
            FaceCorners {
                id: 2,
                surface: quad([verts[1], verts[2], verts[5], verts[4]]),
                corners: [1, 2, 5, 4],
            },
        ],
    )
    .unwrap();
    m.validate().unwrap();
    let a = m.normal_angles(5).unwrap();
    let shared: Vec<f64> = a.iter().flatten().copied().collect();
    assert_eq!(shared.len(), 1, "{a:?}");
    assert!((shared[0] - 30.0).abs() < 1e-9, "{}", shared[0]);
    assert_eq!(a.iter().filter(|x| x.is_none()).count(), 6);
}

/// A 2 x 1 face A with two unit squares B, C on its top side: A has five
/// corners and its top side is a chain of the two edges it shares with B
/// and C.
fn chain_model() -> PatchComplex {
    let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
    let v = vec![
        p(0., 0.),
        p(2., 0.),
        p(2., 1.),
        p(1., 1.),
        p(0., 1.),
        p(0., 2.),
        p(1., 2.),
        p(2., 2.),
    ];
    let sq = |c: [usize; 4]| FaceCorners {
        id: c[0] as i64,
        surface: quad(c.map(|k| v[k])),
        corners: c,
    };
    let mut m =
        PatchComplex::assemble(v.clone(), vec![sq([4, 3, 6, 5]), sq([3, 2, 7, 6])]).unwrap();
    let find = |m: &PatchComplex, a: usize, b: usize| {
        let e = m
            .edges
            .iter()
            .position(|e| (e.start, e.end) == (a.min(b), a.max(b)))
            .unwrap();
        EdgeUse {
            edge: e,
            reversed: a > b,
        }
    };
    for (a, b) in [(0, 1), (1, 2), (0, 4)] {
        m.edges.push(Edge {
            start: a,
            end: b,
            curve: Curve::new(lin(), vec![v[a], v[b]]).unwrap(),
        });
    }
    let sides = [
        vec![find(&m, 0, 1)],
        vec![find(&m, 1, 2)],
        vec![find(&m, 2, 3), find(&m, 3, 4)],
        vec![find(&m, 4, 0)],
    ];
    m.faces.push(Face {
        id: 99,
        surface: quad([p(0., 0.), p(2., 0.), p(2., 1.), p(0., 1.)]),
        sides,
    });
    m
}

#[test]
fn a_side_made_of_two_edges_is_cut_at_their_vertex() {
    let m = chain_model();
    m.validate().unwrap();
    assert_eq!(m.faces[2].side_count(), 4);
    assert_eq!(m.faces[2].use_count(), 5);
    assert_eq!(m.face_vertices(2).unwrap(), vec![0, 1, 2, 3, 4]);
    let r = m.chain_ranges(2, 2).unwrap();
    assert_eq!(r.len(), 2);
    assert!(
        (r[0].0).abs() < 1e-15 && (r[0].1 - 0.5).abs() < 1e-12,
        "{r:?}"
    );
    assert!(
        (r[1].0 - 0.5).abs() < 1e-12 && (r[1].1 - 1.0).abs() < 1e-15,
        "{r:?}"
    );
    assert_eq!(m.chain_ranges(2, 0).unwrap(), vec![(0.0, 1.0)]);
    // both halves of the chain side are shared, each with one square, gap 0
    let users = m.edge_faces();
    let gaps = m.boundary_gaps().unwrap();
    for u in &m.faces[2].sides[2] {
        assert_eq!(users[u.edge].len(), 2);
        assert!(gaps[u.edge].face_gap < 1e-14 && gaps[u.edge].curve_gap < 1e-14);
    }
    assert_eq!(users[m.faces[2].sides[2][1].edge][1].index, 1);
    // flat: no normal angle along the two shared edges
    let angles = m.normal_angles(9).unwrap();
    for u in &m.faces[2].sides[2] {
        assert!(angles[u.edge].unwrap() < 1e-6, "{:?}", angles[u.edge]);
    }
    // the chain's edges listed out of order: not a cycle
    let mut bad = m.clone();
    bad.faces[2].sides[2].swap(0, 1);
    let err = bad.validate().unwrap_err().to_string();
    assert!(err.contains("closed cycle"), "{err}");
    // the junction vertex off the face's side: named with its distance
    let mut bad = m.clone();
    let off = 0.25;
    bad.vertices[3].point.y += off;
    for e in bad.edges.iter_mut() {
        for (end, k) in [(e.start, 0), (e.end, 1)] {
            if end == 3 {
                let mut c = e.curve.control_points().to_vec();
                c[k].y += off;
                e.curve = Curve::new(lin(), c).unwrap();
            }
        }
    }
    let err = bad.validate().unwrap_err().to_string();
    assert!(
        err.contains("side 2: a vertex where its edges meet is 2.5e-1"),
        "{err}"
    );
}
