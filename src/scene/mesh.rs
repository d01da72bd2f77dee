//! Wavefront OBJ meshes: triangles, with their vertex normals where the
//! file has them; polygons are fanned into triangles.
//!
//! Read by hand rather than with a crate so that every error names the
//! OBJ file's line and the operating system's reason (tobj said "read
//! error" for a directory and "face parse error" with no line), and so
//! that a device or a FIFO named as a mesh is refused instead of read
//! without bound.

use glam::{Vec2, Vec3};
use std::io::BufRead;
use std::path::Path;

/// The triangles of an OBJ file, and their vertex normals where the file
/// gives one for every face corner (`f v//vn` or `f v/vt/vn`).
pub struct ObjMesh {
    pub triangles: Vec<[Vec3; 3]>,
    /// Per triangle, its three vertex normals (unit), turned to the side
    /// of the triangle's winding: the file's normals and its winding need
    /// not agree, and shading follows the winding.
    pub normals: Option<Vec<[Vec3; 3]>>,
    /// Per triangle, its corners' texture coordinates as the file gives
    /// them (`vt`), where every face corner has one.
    pub uvs: Option<Vec<[Vec2; 3]>>,
}

/// Coordinates beyond this are refused, as in scene files
/// (`scene::file::LIMIT`): squared distances must stay finite in single
/// precision.
const LIMIT: f32 = 1e15;

/// The triangles of the OBJ file (`v`, `vn` and `f` lines; texture
/// coordinates, groups, smoothing groups and materials are ignored), with
/// their vertex normals if every face corner has one. The error says what
/// is wrong in words, with the file's line where there is one.
pub fn load_obj(path: &Path) -> Result<ObjMesh, String> {
    let shown = path.display();
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot open the OBJ file {shown}: {e}"))?;
    if !meta.is_file() {
        let what = if meta.is_dir() { "a directory" } else { "not a regular file" };
        return Err(format!("cannot read the OBJ file {shown}: it is {what}"));
    }
    let file = std::fs::File::open(path).map_err(|e| format!("cannot open the OBJ file {shown}: {e}"))?;
    let mut reader = std::io::BufReader::with_capacity(1 << 16, file);
    let mut positions: Vec<Vec3> = Vec::new();
    let mut vertex_normals: Vec<Vec3> = Vec::new();
    let mut texcoords: Vec<Vec2> = Vec::new();
    // Face corners as (position, normal) indices, three per triangle, and
    // their texture coordinates' indices.
    let mut corners: Vec<(u32, Option<u32>)> = Vec::new();
    let mut corner_uvs: Vec<Option<u32>> = Vec::new();
    let mut polygon: Vec<(u32, Option<u32>, Option<u32>)> = Vec::new();
    let mut line = String::new();
    let mut number = 0usize;
    loop {
        line.clear();
        let read = reader.read_line(&mut line).map_err(|e| format!("OBJ file {shown}, line {}: {e}", number + 1))?;
        if read == 0 {
            break;
        }
        number += 1;
        let at = |message: String| format!("OBJ file {shown}, line {number}: {message}");
        let mut words = line.split_ascii_whitespace();
        match words.next() {
            Some("v") => positions.push(vector(&mut words, "vertex").map_err(at)?),
            Some("vn") => vertex_normals.push(vector(&mut words, "normal").map_err(at)?),
            Some("vt") => texcoords.push(texcoord(&mut words).map_err(at)?),
            Some("f") => {
                polygon.clear();
                for word in words {
                    polygon.push(corner(word, positions.len(), texcoords.len(), vertex_normals.len()).map_err(at)?);
                }
                if polygon.len() < 3 {
                    return Err(at(format!("a face needs at least 3 vertices, got {}", polygon.len())));
                }
                for i in 1..polygon.len() - 1 {
                    for c in [polygon[0], polygon[i], polygon[i + 1]] {
                        corners.push((c.0, c.2));
                        corner_uvs.push(c.1);
                    }
                }
            }
            _ => {}
        }
    }
    if corners.is_empty() {
        return Err(format!("OBJ file {shown} has no faces"));
    }
    let triangles: Vec<[Vec3; 3]> =
        corners.chunks_exact(3).map(|c| [0, 1, 2].map(|k| positions[c[k].0 as usize])).collect();
    let smooth = corners.iter().all(|c| c.1.is_some());
    let normals = smooth.then(|| {
        corners
            .chunks_exact(3)
            .zip(&triangles)
            .map(|(c, t)| {
                let mut n = [0, 1, 2]
                    .map(|k| vertex_normals[c[k].1.expect("smooth") as usize].try_normalize().unwrap_or(Vec3::ZERO));
                let winding = (t[1] - t[0]).cross(t[2] - t[0]);
                if (n[0] + n[1] + n[2]).dot(winding) < 0.0 {
                    n = n.map(|v| -v);
                }
                n
            })
            .collect()
    });
    let uvs = corner_uvs.iter().all(Option::is_some).then(|| {
        corner_uvs.chunks_exact(3).map(|c| [0, 1, 2].map(|k| texcoords[c[k].expect("all present") as usize])).collect()
    });
    Ok(ObjMesh { triangles, normals, uvs })
}

/// Three finite coordinates within [`LIMIT`] (a fourth, `w`, is allowed and
/// ignored).
fn vector<'a>(words: &mut impl Iterator<Item = &'a str>, what: &str) -> Result<Vec3, String> {
    let mut v = [0.0f32; 3];
    for (i, slot) in v.iter_mut().enumerate() {
        let word = words.next().ok_or_else(|| format!("a {what} needs 3 coordinates, got {i}"))?;
        *slot = word.parse().map_err(|_| format!("{what} coordinate {} is not a number: '{word}'", i + 1))?;
        if !slot.is_finite() || slot.abs() > LIMIT {
            return Err(format!("{what} coordinate {} must be finite and within ±{LIMIT:e}, got {word}", i + 1));
        }
    }
    Ok(Vec3::from_array(v))
}

/// Texture coordinates `u v` (a third, `w`, is allowed and ignored; a
/// missing `v` is 0, as the format allows).
fn texcoord<'a>(words: &mut impl Iterator<Item = &'a str>) -> Result<Vec2, String> {
    let mut v = [0.0f32; 2];
    for (i, slot) in v.iter_mut().enumerate() {
        let Some(word) = words.next() else {
            if i == 0 {
                return Err("texture coordinates need at least u".into());
            }
            break;
        };
        *slot = word.parse().map_err(|_| format!("texture coordinate {} is not a number: '{word}'", i + 1))?;
        if !slot.is_finite() {
            return Err(format!("texture coordinate {} must be finite, got {word}", i + 1));
        }
    }
    Ok(Vec2::from_array(v))
}

/// One face corner, `v`, `v/vt`, `v//vn` or `v/vt/vn`, 1-based or negative
/// (counted back from the last one read), as 0-based indices (position,
/// texture coordinates, normal).
fn corner(
    word: &str,
    positions: usize,
    texcoords: usize,
    normals: usize,
) -> Result<(u32, Option<u32>, Option<u32>), String> {
    let mut parts = word.split('/');
    let index = |text: &str, count: usize, what: &str| -> Result<u32, String> {
        let i: i64 =
            text.parse().map_err(|_| format!("face corner '{word}': {what} index '{text}' is not a whole number"))?;
        let resolved = if i < 0 { count as i64 + i } else { i - 1 };
        if i == 0 || !(0..count as i64).contains(&resolved) {
            return Err(format!("face corner '{word}': {what} {i} does not exist ({count} defined so far)"));
        }
        Ok(resolved as u32)
    };
    let position = index(parts.next().unwrap_or(""), positions, "vertex")?;
    let texture = match parts.next() {
        Some(t) if !t.is_empty() => Some(index(t, texcoords, "texture coordinate")?),
        _ => None,
    };
    let normal = match parts.next() {
        Some(n) if !n.is_empty() => Some(index(n, normals, "normal")?),
        _ => None,
    };
    Ok((position, texture, normal))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(text: &str) -> Result<ObjMesh, String> {
        let dir = std::env::temp_dir().join(format!("photonmap-obj-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!("{:x}.obj", text.len() * 31 + text.bytes().map(|b| b as usize).sum::<usize>()));
        std::fs::write(&path, text).unwrap();
        let mesh = load_obj(&path);
        let _ = std::fs::remove_file(&path);
        mesh
    }

    /// Texture coordinates where every corner has them, per triangle
    /// corner; none where a corner lacks them.
    #[test]
    fn texture_coordinates_follow_the_corners() {
        let m =
            load("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1 0\nvt 0 1\nf 1/1 2/2 3/3 4/4\n").unwrap();
        let uvs = m.uvs.expect("every corner has one");
        assert_eq!(uvs, [[Vec2::ZERO, Vec2::X, Vec2::ONE], [Vec2::ZERO, Vec2::ONE, Vec2::Y]]);
        assert!(load("v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nf 1/1 2 3\n").unwrap().uvs.is_none());
        let e = load("v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nf 1/2 2/1 3/1\n").err().unwrap();
        assert!(e.contains("line 5") && e.contains("texture coordinate 2"), "{e}");
    }

    #[test]
    fn quads_are_fanned_and_every_index_form_reads() {
        let m = load("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2//1 -2//-1 4/1/1\n").unwrap();
        assert_eq!(m.triangles.len(), 2);
        assert_eq!(m.triangles[1], [Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)]);
        assert_eq!(m.normals.unwrap()[0], [Vec3::Z; 3]);
        // One corner without a normal: the mesh is shaded flat.
        assert!(load("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3\n").unwrap().normals.is_none());
    }

    #[test]
    fn errors_name_the_line() {
        for (text, line, words) in [
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", 4, "'x' is not a whole number"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 9\n", 5, "vertex 9 does not exist (3 defined so far)"),
            ("v 0 0\n", 1, "a vertex needs 3 coordinates, got 2"),
            ("v 0 0 1e30\n", 1, "within"),
            ("v 0 0 nan\n", 1, "must be finite"),
            ("v 0 0 0\nv 1 0 0\nf 1 2\n", 3, "at least 3 vertices"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n", 4, "normal 1 does not exist"),
        ] {
            let e = load(text).err().unwrap_or_default();
            assert!(e.contains(&format!("line {line}:")) && e.contains(words), "{text:?}: {e}");
        }
        assert!(load("v 0 0 0\n").err().unwrap().contains("has no faces"));
    }

    #[test]
    fn directories_and_devices_are_refused_with_the_reason() {
        let e = load_obj(&std::env::temp_dir()).err().unwrap();
        assert!(e.contains("it is a directory"), "{e}");
        if Path::new("/dev/zero").exists() {
            let e = load_obj(Path::new("/dev/zero")).err().unwrap();
            assert!(e.contains("not a regular file"), "{e}");
        }
        let e = load_obj(Path::new("/nonexistent/x.obj")).err().unwrap();
        assert!(e.contains("No such file"), "{e}");
    }
}
