//! Triangle meshes as binary PLY (little-endian), the format Mitsuba reads
//! fastest: vertices shared where position and normal are bit-identical,
//! vertex normals written only for smooth meshes, texture coordinates only
//! for meshes that have their own.

use glam::{Vec2, Vec3};
use std::collections::HashMap;

/// A mesh being collected: its triangles, each with its vertex normals if
/// it is smooth.
#[derive(Default)]
pub struct PlyMesh {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    faces: Vec<[u32; 3]>,
    index: HashMap<[u32; 8], u32>,
    smooth: bool,
    textured: bool,
}

impl PlyMesh {
    /// An empty mesh, with vertex normals (`smooth`) or without.
    pub fn new(smooth: bool) -> Self {
        PlyMesh { smooth, ..Default::default() }
    }

    /// An empty mesh whose vertices carry texture coordinates.
    pub fn textured(smooth: bool) -> Self {
        PlyMesh { smooth, textured: true, ..Default::default() }
    }

    pub fn is_textured(&self) -> bool {
        self.textured
    }

    pub fn is_smooth(&self) -> bool {
        self.smooth
    }

    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// Adds a triangle wound as given; `normals` is used when the mesh is smooth.
    pub fn push(&mut self, vertices: [Vec3; 3], normals: [Vec3; 3]) {
        self.push_uv(vertices, normals, [Vec2::ZERO; 3]);
    }

    /// Adds a triangle with texture coordinates (used where the mesh is
    /// textured).
    pub fn push_uv(&mut self, vertices: [Vec3; 3], normals: [Vec3; 3], uvs: [Vec2; 3]) {
        let face = [0, 1, 2].map(|k| {
            let n = if self.smooth { normals[k] } else { Vec3::ZERO };
            let t = if self.textured { uvs[k] } else { Vec2::ZERO };
            let p = vertices[k];
            let key = [p.x, p.y, p.z, n.x, n.y, n.z, t.x, t.y].map(f32::to_bits);
            *self.index.entry(key).or_insert_with(|| {
                self.positions.push(p);
                self.normals.push(n);
                self.uvs.push(t);
                self.positions.len() as u32 - 1
            })
        });
        self.faces.push(face);
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut header = format!(
            "ply\nformat binary_little_endian 1.0\ncomment written by photonmap\nelement vertex {}\n\
             property float x\nproperty float y\nproperty float z\n",
            self.positions.len()
        );
        if self.smooth {
            header += "property float nx\nproperty float ny\nproperty float nz\n";
        }
        if self.textured {
            header += "property float u\nproperty float v\n";
        }
        header += &format!("element face {}\nproperty list uchar int vertex_indices\nend_header\n", self.faces.len());
        let per_vertex = 12 + if self.smooth { 12 } else { 0 } + if self.textured { 8 } else { 0 };
        let mut out = Vec::with_capacity(header.len() + self.positions.len() * per_vertex + self.faces.len() * 13);
        out.extend_from_slice(header.as_bytes());
        for ((p, n), t) in self.positions.iter().zip(&self.normals).zip(&self.uvs) {
            for v in p.to_array() {
                out.extend_from_slice(&v.to_le_bytes());
            }
            if self.smooth {
                for v in n.to_array() {
                    out.extend_from_slice(&v.to_le_bytes());
                }
            }
            if self.textured {
                for v in t.to_array() {
                    out.extend_from_slice(&v.to_le_bytes());
                }
            }
        }
        for f in &self.faces {
            out.push(3);
            for i in f {
                out.extend_from_slice(&(*i as i32).to_le_bytes());
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_vertices_and_the_header_count_them() {
        let mut m = PlyMesh::new(false);
        let (a, b, c, d) = (Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE);
        m.push([a, b, c], [Vec3::Z; 3]);
        m.push([b, d, c], [Vec3::Z; 3]);
        let bytes = m.to_bytes();
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.contains("element vertex 4\n") && text.contains("element face 2\n"));
        assert!(!text.contains("nx"));
        let body = bytes.len() - (text.find("end_header\n").unwrap() + "end_header\n".len());
        assert_eq!(body, 4 * 12 + 2 * 13);
        // With normals, a vertex of another normal is another vertex.
        let mut s = PlyMesh::new(true);
        s.push([a, b, c], [Vec3::Z; 3]);
        s.push([b, d, c], [Vec3::X; 3]);
        assert!(String::from_utf8_lossy(&s.to_bytes()).contains("element vertex 6\n"));
    }
}
