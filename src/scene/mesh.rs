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
