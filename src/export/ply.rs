//! Triangle meshes as binary PLY (little-endian), the format Mitsuba reads
//! fastest: vertices shared where position and normal are bit-identical,
//! vertex normals written only for smooth meshes, texture coordinates only
//! for meshes that have their own, and the scene's mesh attributes
//! (`mesh_attribute` textures) as vertex properties.

use crate::math::Color;
use glam::{Vec2, Vec3};
use std::collections::HashMap;

/// A mesh attribute the mesh carries: written as the float vertex
/// properties `{name}_x {name}_y {name}_z`, or `{name}_x` alone where it
/// is grey, which Mitsuba's PLY reader (src/shapes/ply.h,
/// `find_other_fields`) and photonmap's group into the attribute
/// `vertex_{name}` of 3 or 1 values. (Not `_r _g _b`: Mitsuba names those
/// `vertex_{name}_color`; nor a name without a postfix, which it ignores.)
#[derive(Clone, Debug, PartialEq)]
pub struct VertexAttribute {
    pub name: String,
    pub grey: bool,
}

/// A mesh being collected: its triangles, each with its vertex normals if
/// it is smooth.
#[derive(Default)]
pub struct PlyMesh {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    /// Per vertex, each attribute's value (`attributes.len()` in a row).
    values: Vec<Color>,
    attributes: Vec<VertexAttribute>,
    faces: Vec<[u32; 3]>,
    /// A vertex's position, normal and coordinates, and its attribute
    /// values (none where the mesh carries none: no allocation).
    index: HashMap<([u32; 8], Vec<u32>), u32>,
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

    /// The mesh with these attributes (given at each corner by
    /// [`Self::push_corners`]).
    pub fn with_attributes(self, attributes: Vec<VertexAttribute>) -> Self {
        PlyMesh { attributes, ..self }
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
        self.push_corners(vertices, normals, uvs, |_, _| Color::ZERO);
    }

    /// Adds a triangle with texture coordinates and, for each attribute
    /// `a` the mesh carries, its value `value(a, k)` at corner `k`: a
    /// vertex shared by triangles of other values is written once for
    /// each (a face attribute becomes a vertex one, constant over the face).
    pub fn push_corners(
        &mut self,
        vertices: [Vec3; 3],
        normals: [Vec3; 3],
        uvs: [Vec2; 3],
        value: impl Fn(usize, usize) -> Color,
    ) {
        let face = [0, 1, 2].map(|k| {
            let n = if self.smooth { normals[k] } else { Vec3::ZERO };
            let t = if self.textured { uvs[k] } else { Vec2::ZERO };
            let p = vertices[k];
            let values: Vec<Color> = (0..self.attributes.len()).map(|a| value(a, k)).collect();
            let key = (
                [p.x, p.y, p.z, n.x, n.y, n.z, t.x, t.y].map(f32::to_bits),
                values.iter().flat_map(|c| c.to_array().map(f32::to_bits)).collect(),
            );
            *self.index.entry(key).or_insert_with(|| {
                self.positions.push(p);
                self.normals.push(n);
                self.uvs.push(t);
                self.values.extend(values);
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
        for a in &self.attributes {
            if a.grey {
                header += &format!("property float {}_x\n", a.name);
            } else {
                for c in ["x", "y", "z"] {
                    header += &format!("property float {}_{c}\n", a.name);
                }
            }
        }
        header += &format!("element face {}\nproperty list uchar int vertex_indices\nend_header\n", self.faces.len());
        let per_vertex = 12
            + if self.smooth { 12 } else { 0 }
            + if self.textured { 8 } else { 0 }
            + self.attributes.iter().map(|a| if a.grey { 4 } else { 12 }).sum::<usize>();
        let mut out = Vec::with_capacity(header.len() + self.positions.len() * per_vertex + self.faces.len() * 13);
        out.extend_from_slice(header.as_bytes());
        let stride = self.attributes.len();
        for (i, ((p, n), t)) in self.positions.iter().zip(&self.normals).zip(&self.uvs).enumerate() {
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
            for (a, c) in self.attributes.iter().zip(&self.values[i * stride..(i + 1) * stride]) {
                let channels = if a.grey { &c.to_array()[..1] } else { &c.to_array()[..] };
                for v in channels {
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

    /// Attributes: three properties for a colour, one for a grey; a
    /// corner of another value is another vertex.
    #[test]
    fn attributes_are_vertex_properties() {
        let attributes = vec![
            VertexAttribute { name: "attr0".into(), grey: false },
            VertexAttribute { name: "attr2".into(), grey: true },
        ];
        let mut m = PlyMesh::new(false).with_attributes(attributes);
        let (a, b, c, d) = (Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE);
        let red = Color::new(1.0, 0.0, 0.0);
        m.push_corners([a, b, c], [Vec3::Z; 3], [Vec2::ZERO; 3], |_, _| red);
        m.push_corners([b, d, c], [Vec3::Z; 3], [Vec2::ZERO; 3], |_, k| if k == 0 { red } else { Color::ONE });
        let bytes = m.to_bytes();
        let text = String::from_utf8_lossy(&bytes);
        let header = "property float attr0_x\nproperty float attr0_y\nproperty float attr0_z\nproperty float attr2_x\n";
        assert!(text.contains(header), "{text}");
        // b is shared (red at both); c is not.
        assert!(text.contains("element vertex 5\n"), "{text}");
        let body = bytes.len() - (text.find("end_header\n").unwrap() + "end_header\n".len());
        assert_eq!(body, 5 * (12 + 16) + 2 * 13);
        // The last vertex, c again: white, and its grey value 1.
        let end = bytes.len() - 2 * 13;
        let last: Vec<f32> =
            bytes[end - 28..end].chunks(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        assert_eq!(last, [0.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0]);
    }
}
