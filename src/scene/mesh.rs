//! Wavefront OBJ meshes (read with tobj): triangles only, positions only;
//! polygons are fanned into triangles.

use glam::Vec3;
use std::path::Path;

/// The triangles of every model in the OBJ file, as vertex triples. The
/// error says what is wrong in words (missing file, a malformed line, an
/// index out of range).
pub fn load_obj(path: &Path) -> Result<Vec<[Vec3; 3]>, String> {
    let options = tobj::LoadOptions { triangulate: true, single_index: true, ignore_points: true, ignore_lines: true };
    let (models, _) = tobj::load_obj(path, &options).map_err(|e| match e {
        tobj::LoadError::OpenFileFailed => format!("cannot open the OBJ file {}", path.display()),
        e => format!("malformed OBJ file {}: {e}", path.display()),
    })?;
    let mut triangles = Vec::new();
    for m in &models {
        let positions = &m.mesh.positions;
        let vertex = |i: u32| -> Result<Vec3, String> {
            let i = i as usize;
            if 3 * i + 2 >= positions.len() {
                return Err(format!("OBJ file {}: model '{}' refers to vertex {} of {}", path.display(), m.name, i + 1, positions.len() / 3));
            }
            let v = Vec3::new(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
            if !v.is_finite() {
                return Err(format!("OBJ file {}: vertex {} is not finite", path.display(), i + 1));
            }
            Ok(v)
        };
        for f in m.mesh.indices.chunks_exact(3) {
            triangles.push([vertex(f[0])?, vertex(f[1])?, vertex(f[2])?]);
        }
    }
    if triangles.is_empty() {
        return Err(format!("OBJ file {} has no faces", path.display()));
    }
    Ok(triangles)
}
