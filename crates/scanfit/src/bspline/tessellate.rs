//! Tessellation of a surface into a triangle mesh on a regular parameter grid.

use super::{BasisWorkspace, Surface};
use crate::{Point3, Vector3};

/// A triangle mesh with per-vertex normals and parameters.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub vertices: Vec<Point3>,
    /// Unit normals (`S_u x S_v`; zero where the surface is degenerate).
    pub normals: Vec<Vector3>,
    /// Parameters of each vertex.
    pub uv: Vec<[f64; 2]>,
    /// Counter-clockwise triangles (in `(u, v)`), as vertex indices.
    pub triangles: Vec<[u32; 3]>,
}

/// Tessellates `surface` with `(nu + 1) x (nv + 1)` vertices (each at least 1).
pub fn tessellate(surface: &Surface, nu: usize, nv: usize) -> Mesh {
    let (nu, nv) = (nu.max(1), nv.max(1));
    let ((u0, u1), (v0, v1)) = surface.domain();
    let (p, q) = surface.degrees();
    let (mut wu, mut wv) = (BasisWorkspace::new(p, 1), BasisWorkspace::new(q, 1));
    let mut d = [Vector3::zeros(); 4];
    let mut mesh = Mesh::default();
    for i in 0..=nu {
        let u = u0 + (u1 - u0) * i as f64 / nu as f64;
        for j in 0..=nv {
            let v = v0 + (v1 - v0) * j as f64 / nv as f64;
            surface.derivatives_into(u, v, &mut wu, &mut wv, 1, &mut d);
            let n = d[2].cross(&d[1]);
            let len = n.norm();
            mesh.vertices.push(Point3::from(d[0]));
            mesh.normals.push(if len > 0.0 { n / len } else { n });
            mesh.uv.push([u, v]);
        }
    }
    let w = (nv + 1) as u32;
    for i in 0..nu as u32 {
        for j in 0..nv as u32 {
            let (a, b, c, e) = (
                i * w + j,
                (i + 1) * w + j,
                (i + 1) * w + j + 1,
                i * w + j + 1,
            );
            mesh.triangles.push([a, b, c]);
            mesh.triangles.push([a, c, e]);
        }
    }
    mesh
}
