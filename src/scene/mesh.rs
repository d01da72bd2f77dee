//! Wavefront OBJ meshes (read with tobj): triangles, with their vertex
//! normals where the file has them; polygons are fanned into triangles.

use glam::Vec3;
use std::path::Path;

/// The triangles of an OBJ file, and their vertex normals where the file
/// gives one for every vertex (`vn`).
pub struct ObjMesh {
    pub triangles: Vec<[Vec3; 3]>,
    /// Per triangle, its three vertex normals (unit), turned to the side
    /// of the triangle's winding: the file's normals and its winding need
    /// not agree, and shading follows the winding.
    pub normals: Option<Vec<[Vec3; 3]>>,
}

/// The triangles of every model in the OBJ file, as vertex triples, with
/// their vertex normals if every model has them. The error says what is
/// wrong in words (missing file, a malformed line, an index out of range).
pub fn load_obj(path: &Path) -> Result<ObjMesh, String> {
    let options = tobj::LoadOptions { triangulate: true, single_index: true, ignore_points: true, ignore_lines: true };
    let (models, _) = tobj::load_obj(path, &options).map_err(|e| match e {
        tobj::LoadError::OpenFileFailed => format!("cannot open the OBJ file {}", path.display()),
        e => format!("malformed OBJ file {}: {e}", path.display()),
    })?;
    let smooth = models.iter().all(|m| !m.mesh.normals.is_empty() && m.mesh.normals.len() == m.mesh.positions.len());
    let mut triangles = Vec::new();
    let mut normals = Vec::new();
    for m in &models {
        let positions = &m.mesh.positions;
        let read = |data: &[f32], i: u32, what: &str| -> Result<Vec3, String> {
            let i = i as usize;
            if 3 * i + 2 >= data.len() {
                return Err(format!(
                    "OBJ file {}: model '{}' refers to {what} {} of {}",
                    path.display(),
                    m.name,
                    i + 1,
                    data.len() / 3
                ));
            }
            let v = Vec3::new(data[3 * i], data[3 * i + 1], data[3 * i + 2]);
            if !v.is_finite() {
                return Err(format!("OBJ file {}: {what} {} is not finite", path.display(), i + 1));
            }
            Ok(v)
        };
        for f in m.mesh.indices.chunks_exact(3) {
            let t =
                [read(positions, f[0], "vertex")?, read(positions, f[1], "vertex")?, read(positions, f[2], "vertex")?];
            if smooth {
                let n = [f[0], f[1], f[2]].map(|i| read(&m.mesh.normals, i, "normal"));
                let mut n =
                    [n[0].clone()?, n[1].clone()?, n[2].clone()?].map(|v| v.try_normalize().unwrap_or(Vec3::ZERO));
                let winding = (t[1] - t[0]).cross(t[2] - t[0]);
                if (n[0] + n[1] + n[2]).dot(winding) < 0.0 {
                    n = n.map(|v| -v);
                }
                normals.push(n);
            }
            triangles.push(t);
        }
    }
    if triangles.is_empty() {
        return Err(format!("OBJ file {} has no faces", path.display()));
    }
    Ok(ObjMesh { triangles, normals: smooth.then_some(normals) })
}

/// A torus around the z axis through `center` (radii `major` > `minor`),
/// as 2 x `around` x `tube` triangles wound with outward normals: the
/// procedural mesh of the BVH benchmarks (250 x 200: 100,000 triangles).
pub fn torus(center: Vec3, major: f32, minor: f32, around: u32, tube: u32) -> Vec<[Vec3; 3]> {
    let point = |i: u32, j: u32| {
        let u = std::f32::consts::TAU * (i % around) as f32 / around as f32;
        let v = std::f32::consts::TAU * (j % tube) as f32 / tube as f32;
        let r = major + minor * v.cos();
        center + Vec3::new(r * u.cos(), r * u.sin(), minor * v.sin())
    };
    let mut triangles = Vec::with_capacity(2 * (around * tube) as usize);
    for i in 0..around {
        for j in 0..tube {
            let (a, b, c, d) = (point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    triangles
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torus_is_closed_with_outward_normals() {
        let c = Vec3::new(1.0, 2.0, 3.0);
        let tris = torus(c, 2.0, 0.5, 40, 30);
        assert_eq!(tris.len(), 2400);
        for [a, b, t] in &tris {
            let n = (*b - *a).cross(*t - *a);
            let centroid = (*a + *b + *t) / 3.0;
            // The tube's centre line point nearest the centroid.
            let p = centroid - c;
            let ring = c + Vec3::new(p.x, p.y, 0.0).normalize() * 2.0;
            assert!(n.dot(centroid - ring) > 0.0, "inward triangle");
        }
        // Closed: every edge is shared by exactly two triangles.
        let key = |p: Vec3| (p * 1e4).round().as_ivec3().to_array();
        let mut edges = std::collections::HashMap::new();
        for t in &tris {
            for k in 0..3 {
                let (a, b) = (key(t[k]), key(t[(k + 1) % 3]));
                *edges.entry(if a < b { (a, b) } else { (b, a) }).or_insert(0) += 1;
            }
        }
        assert!(edges.values().all(|&n| n == 2));
    }
}
