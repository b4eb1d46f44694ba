//! glTF 2.0 binary (`.glb`) export of triangle meshes, so that any web or
//! desktop viewer shows a fitted surface: positions (f32, relative to the
//! mesh's centre, which goes into the node's translation to keep precision for
//! georeferenced data), normals, optional per-vertex colours, u32 indices.

use scanfit::bspline::Mesh;

/// A `.glb` file of `mesh` with optional RGB colours per vertex.
pub fn mesh_glb(mesh: &Mesh, colours: Option<&[[u8; 3]]>, name: &str) -> Vec<u8> {
    let n = mesh.vertices.len();
    let centre = if n > 0 {
        mesh.vertices
            .iter()
            .fold(nalgebra::Vector3::zeros(), |a, p| a + p.coords)
            / n as f64
    } else {
        nalgebra::Vector3::zeros()
    };
    let mut bin: Vec<u8> = Vec::new();
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in &mesh.vertices {
        let q = p.coords - centre;
        for c in 0..3 {
            let v = q[c] as f32;
            lo[c] = lo[c].min(v);
            hi[c] = hi[c].max(v);
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    let normals_offset = bin.len();
    for nrm in &mesh.normals {
        for c in 0..3 {
            bin.extend_from_slice(&(nrm[c] as f32).to_le_bytes());
        }
    }
    let colours_offset = bin.len();
    if let Some(cols) = colours {
        // normalised unsigned bytes, padded to 4 bytes per vertex
        for c in cols {
            bin.extend_from_slice(&[c[0], c[1], c[2], 255]);
        }
    }
    let indices_offset = bin.len();
    for t in &mesh.triangles {
        for &k in t {
            bin.extend_from_slice(&k.to_le_bytes());
        }
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let f = |v: f32| if v.is_finite() { v } else { 0.0 };
    let mut attributes = serde_json::json!({"POSITION": 0, "NORMAL": 1});
    let mut views = vec![
        serde_json::json!({"buffer": 0, "byteOffset": 0, "byteLength": normals_offset, "target": 34962}),
        serde_json::json!({"buffer": 0, "byteOffset": normals_offset, "byteLength": colours_offset - normals_offset, "target": 34962}),
    ];
    let mut accessors = vec![
        serde_json::json!({"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
            "min": [f(lo[0]), f(lo[1]), f(lo[2])], "max": [f(hi[0]), f(hi[1]), f(hi[2])]}),
        serde_json::json!({"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"}),
    ];
    if colours.is_some() {
        views.push(serde_json::json!({"buffer": 0, "byteOffset": colours_offset, "byteLength": indices_offset - colours_offset, "target": 34962}));
        accessors.push(serde_json::json!({"bufferView": views.len() - 1, "componentType": 5121, "normalized": true, "count": n, "type": "VEC4"}));
        attributes["COLOR_0"] = serde_json::json!(accessors.len() - 1);
    }
    views.push(serde_json::json!({"buffer": 0, "byteOffset": indices_offset, "byteLength": mesh.triangles.len() * 12, "target": 34963}));
    accessors.push(serde_json::json!({"bufferView": views.len() - 1, "componentType": 5125, "count": mesh.triangles.len() * 3, "type": "SCALAR"}));
    let doc = serde_json::json!({
        "asset": {"version": "2.0", "generator": format!("scanfit {}", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": name, "translation": [centre.x, centre.y, centre.z]}],
        "meshes": [{"name": name, "primitives": [{"attributes": attributes, "indices": accessors.len() - 1, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.85, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.7}, "doubleSided": true}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}],
    });
    let mut json = doc.to_string().into_bytes();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use scanfit::bspline::{tessellate, KnotVector, Surface};
    use scanfit::Point3;

    #[test]
    fn glb_layout_is_consistent() {
        let s = Surface::new(
            KnotVector::uniform_clamped(1, 2).unwrap(),
            KnotVector::uniform_clamped(1, 2).unwrap(),
            vec![
                Point3::new(1e6, 0., 0.),
                Point3::new(1e6, 1., 0.),
                Point3::new(1e6 + 1., 0., 0.),
                Point3::new(1e6 + 1., 1., 1.),
            ],
        )
        .unwrap();
        let m = tessellate(&s, 4, 3);
        let cols = vec![[10u8, 20, 30]; m.vertices.len()];
        let glb = mesh_glb(&m, Some(&cols), "t");
        assert_eq!(&glb[0..4], b"glTF");
        assert_eq!(
            u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize,
            glb.len()
        );
        let jlen = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
        let doc: serde_json::Value = serde_json::from_slice(&glb[20..20 + jlen]).unwrap();
        let blen = u32::from_le_bytes(glb[20 + jlen..24 + jlen].try_into().unwrap()) as usize;
        assert_eq!(doc["buffers"][0]["byteLength"], blen);
        assert_eq!(doc["accessors"][0]["count"], 20);
        // every view lies inside the buffer
        for v in doc["bufferViews"].as_array().unwrap() {
            let end = v["byteOffset"].as_u64().unwrap() + v["byteLength"].as_u64().unwrap();
            assert!(end as usize <= blen);
        }
        // positions are stored relative to the centre (precision for large coordinates)
        assert!(doc["accessors"][0]["max"][0].as_f64().unwrap() < 1.0);
    }
}
