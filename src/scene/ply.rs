//! Stanford PLY meshes (Turk 1994; the layout as documented by Paul Bourke,
//! "PLY - Polygon File Format"): ASCII and binary of either byte order,
//! positions, vertex normals, texture coordinates, vertex colours, and
//! polygons fanned into triangles.
//!
//! Read by hand, like OBJ (`mesh.rs`), so that an error names the line (in
//! ASCII) or byte (in binary) where the file goes wrong, and a device or a
//! FIFO is refused instead of read without bound.

use glam::{Vec2, Vec3};
use std::path::Path;

/// An indexed triangle mesh.
#[derive(Debug, Clone, Default)]
pub struct PlyMesh {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
    /// Per vertex colour (0..1), from `red`/`green`/`blue` (or `r`, `g`, `b`).
    pub colors: Option<Vec<Vec3>>,
    pub triangles: Vec<[u32; 3]>,
    /// The other properties of vertices and faces, grouped as Mitsuba 3
    /// groups them (ply.cpp): `{prefix}_{x|y|z|w}`, `_{r|g|b|a}`,
    /// `_{0|1|2|3}` or `_{1|2|3|4}` in a row make one attribute
    /// `vertex_{prefix}` or `face_{prefix}` (`vertex_{prefix}_color` for
    /// `_{r|g|b|a}`, as ply.h's `find_other_fields` names it, though its
    /// documentation says otherwise); `r g b (a)` or `red green blue
    /// (alpha)` make `*_color`; any other property is one of its own.
    pub attributes: Vec<Attribute>,
}

/// A vertex or face attribute: `dim` values per vertex, or per triangle
/// (a face's values repeated for each triangle it is fanned into).
#[derive(Debug, Clone, PartialEq)]
pub struct Attribute {
    pub name: String,
    pub per_face: bool,
    pub dim: usize,
    pub values: Vec<f32>,
}

impl Attribute {
    /// The value at vertex or triangle `i` as a colour: one value is
    /// grey, two or more fill the channels in order.
    pub fn color(&self, i: usize) -> Vec3 {
        let v = &self.values[i * self.dim..(i + 1) * self.dim];
        match v.len() {
            1 => Vec3::splat(v[0]),
            2 => Vec3::new(v[0], v[1], 0.0),
            _ => Vec3::new(v[0], v[1], v[2]),
        }
    }
}

/// Groups the properties at `candidates` (index, name) into attributes:
/// (name without the element's prefix, property indices).
fn group_attributes(candidates: &[(usize, String)]) -> Vec<(String, Vec<usize>)> {
    const SCHEMES: [[&str; 4]; 4] =
        [["x", "y", "z", "w"], ["r", "g", "b", "a"], ["0", "1", "2", "3"], ["1", "2", "3", "4"]];
    const COLOURS: [[&str; 4]; 2] = [["r", "g", "b", "a"], ["red", "green", "blue", "alpha"]];
    let mut out = Vec::new();
    let mut i = 0;
    while i < candidates.len() {
        let name = &candidates[i].1;
        let run = |prefix: &str, scheme: &[&str; 4], joined: bool| -> usize {
            let mut n = 0;
            while n < 4 && i + n < candidates.len() {
                let want = if joined { format!("{prefix}_{}", scheme[n]) } else { scheme[n].to_string() };
                if candidates[i + n].1 != want {
                    break;
                }
                n += 1;
            }
            n
        };
        let mut taken = None;
        for c in COLOURS {
            let n = run("", &c, false);
            if n >= 3 {
                taken = Some(("color".to_string(), n));
            }
        }
        if taken.is_none() {
            if let Some((prefix, _)) = name.rsplit_once('_') {
                for sch in SCHEMES {
                    let n = run(prefix, &sch, true);
                    if n >= 1 && name.ends_with(&format!("_{}", sch[0])) {
                        // ply.h names an `_r _g _b` group `{prefix}_color`.
                        let colour = if sch[0] == "r" { "_color" } else { "" };
                        taken = Some((format!("{prefix}{colour}"), n));
                        break;
                    }
                }
            }
        }
        let (group, n) = taken.unwrap_or((name.clone(), 1));
        out.push((group, candidates[i..i + n].iter().map(|c| c.0).collect()));
        i += n;
    }
    out
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    /// Whether an integer colour channel is scaled from 0..255.
    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Debug)]
enum Property {
    Scalar(String, Scalar),
    List(String, Scalar, Scalar),
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

#[derive(Clone, Copy, PartialEq)]
enum Format {
    Ascii,
    Little,
    Big,
}

/// Coordinates beyond this are refused, as in the other readers.
const LIMIT: f64 = 1e15;
/// Most vertices or faces in a file (indices are 32-bit).
const MAX_COUNT: usize = 1 << 30;

pub fn load_ply(path: &Path) -> Result<PlyMesh, String> {
    let shown = path.display();
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot open the PLY file {shown}: {e}"))?;
    if !meta.is_file() {
        return Err(format!("cannot read the PLY file {shown}: it is not a regular file"));
    }
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read the PLY file {shown}: {e}"))?;
    parse(&bytes).map_err(|e| format!("PLY file {shown}, {e}"))
}

/// Parses a PLY file's bytes; errors name the line or byte.
pub fn parse(bytes: &[u8]) -> Result<PlyMesh, String> {
    // The header is ASCII lines up to `end_header`.
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let mut next_line = |pos: &mut usize| -> Option<(usize, String)> {
        if *pos >= bytes.len() {
            return None;
        }
        let end = bytes[*pos..].iter().position(|&b| b == b'\n').map_or(bytes.len(), |i| *pos + i);
        let line = String::from_utf8_lossy(&bytes[*pos..end]).trim_end_matches('\r').to_string();
        *pos = (end + 1).min(bytes.len());
        line_no += 1;
        Some((line_no, line))
    };
    match next_line(&mut pos) {
        Some((_, l)) if l.trim() == "ply" => {}
        _ => return Err("line 1: not a PLY file (it must start with 'ply')".into()),
    }
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let Some((n, line)) = next_line(&mut pos) else {
            return Err("the header has no end_header".into());
        };
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        let at = |m: String| format!("line {n}: {m}");
        match words.first().copied() {
            Some("format") => {
                format = Some(match words.get(1).copied() {
                    Some("ascii") => Format::Ascii,
                    Some("binary_little_endian") => Format::Little,
                    Some("binary_big_endian") => Format::Big,
                    other => return Err(at(format!("unknown format {other:?}"))),
                });
            }
            Some("element") => {
                let (Some(name), Some(count)) = (words.get(1), words.get(2)) else {
                    return Err(at("an element needs a name and a count".into()));
                };
                let count: usize = count.parse().map_err(|_| at(format!("'{count}' is not a count")))?;
                if count > MAX_COUNT {
                    return Err(at(format!("{count} {name}s are more than {MAX_COUNT}")));
                }
                elements.push(Element { name: name.to_string(), count, properties: Vec::new() });
            }
            Some("property") => {
                let Some(e) = elements.last_mut() else {
                    return Err(at("a property before any element".into()));
                };
                let p = if words.get(1) == Some(&"list") {
                    match (
                        words.get(2).and_then(|s| Scalar::parse(s)),
                        words.get(3).and_then(|s| Scalar::parse(s)),
                        words.get(4),
                    ) {
                        (Some(c), Some(v), Some(name)) => Property::List(name.to_string(), c, v),
                        _ => return Err(at("a list property is 'property list COUNT_TYPE ITEM_TYPE NAME'".into())),
                    }
                } else {
                    match (words.get(1).and_then(|s| Scalar::parse(s)), words.get(2)) {
                        (Some(t), Some(name)) => Property::Scalar(name.to_string(), t),
                        _ => return Err(at(format!("unknown property '{line}'"))),
                    }
                };
                e.properties.push(p);
            }
            Some("end_header") => break,
            Some("comment") | Some("obj_info") | None => {}
            Some(w) => return Err(at(format!("unknown header keyword '{w}'"))),
        }
    }
    let format = format.ok_or("the header has no format line")?;
    let mut body = Body { bytes, pos, format, line: line_no, words: Vec::new(), word: 0 };
    let mut mesh = PlyMesh::default();
    for e in &elements {
        match e.name.as_str() {
            "vertex" => read_vertices(e, &mut body, &mut mesh)?,
            "face" => read_faces(e, &mut body, &mut mesh)?,
            _ => {
                // Other elements are skipped, value by value.
                for _ in 0..e.count {
                    for p in &e.properties {
                        match p {
                            Property::Scalar(_, t) => {
                                body.value(*t)?;
                            }
                            Property::List(_, c, t) => {
                                let k = body.count(*c)?;
                                for _ in 0..k {
                                    body.value(*t)?;
                                }
                            }
                        }
                    }
                    body.end_item()?;
                }
            }
        }
    }
    if mesh.triangles.is_empty() {
        return Err("the file has no faces".into());
    }
    Ok(mesh)
}

fn read_vertices(e: &Element, body: &mut Body, mesh: &mut PlyMesh) -> Result<(), String> {
    let index = |names: &[&str]| {
        e.properties.iter().position(|p| matches!(p, Property::Scalar(n, _) if names.contains(&n.as_str())))
    };
    let [x, y, z] = [index(&["x"]), index(&["y"]), index(&["z"])];
    let (Some(x), Some(y), Some(z)) = (x, y, z) else {
        return Err("the vertex element needs x, y and z".into());
    };
    let normal = [index(&["nx"]), index(&["ny"]), index(&["nz"])];
    let uv = [index(&["u", "s", "texture_u", "texture_s"]), index(&["v", "t", "texture_v", "texture_t"])];
    let color = [index(&["red", "r"]), index(&["green", "g"]), index(&["blue", "b"])];
    let has_normals = normal.iter().all(Option::is_some);
    let has_uv = uv.iter().all(Option::is_some);
    let has_color = color.iter().all(Option::is_some);
    let reserved =
        ["x", "y", "z", "nx", "ny", "nz", "u", "v", "s", "t", "texture_u", "texture_s", "texture_v", "texture_t"];
    let candidates: Vec<(usize, String)> = e
        .properties
        .iter()
        .enumerate()
        .filter_map(|(i, p)| match p {
            Property::Scalar(n, _) if !reserved.contains(&n.as_str()) => Some((i, n.clone())),
            _ => None,
        })
        .collect();
    let groups = group_attributes(&candidates);
    let first = mesh.attributes.len();
    for (name, ix) in &groups {
        mesh.attributes.push(Attribute {
            name: format!("vertex_{name}"),
            per_face: false,
            dim: ix.len(),
            values: Vec::new(),
        });
    }
    let mut values = vec![0f64; e.properties.len()];
    let (mut normals, mut uvs, mut colors) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..e.count {
        for (slot, p) in values.iter_mut().zip(&e.properties) {
            *slot = match p {
                Property::Scalar(_, t) => {
                    let v = body.value(*t)?;
                    if !v.is_finite() || v.abs() > LIMIT {
                        return Err(body.at(format!("a vertex value must be finite and within ±{LIMIT:e}, got {v}")));
                    }
                    v
                }
                Property::List(_, c, t) => {
                    let k = body.count(*c)?;
                    for _ in 0..k {
                        body.value(*t)?;
                    }
                    0.0
                }
            };
        }
        body.end_item()?;
        for (a, (_, ix)) in mesh.attributes[first..].iter_mut().zip(&groups) {
            a.values.extend(ix.iter().map(|&i| values[i] as f32));
        }
        mesh.positions.push(Vec3::new(values[x] as f32, values[y] as f32, values[z] as f32));
        if has_normals {
            normals.push(Vec3::new(
                values[normal[0].unwrap()] as f32,
                values[normal[1].unwrap()] as f32,
                values[normal[2].unwrap()] as f32,
            ));
        }
        if has_uv {
            uvs.push(Vec2::new(values[uv[0].unwrap()] as f32, values[uv[1].unwrap()] as f32));
        }
        if has_color {
            let scale = |i: usize| match &e.properties[i] {
                Property::Scalar(_, t) if t.is_integer() => 1.0 / 255.0,
                _ => 1.0,
            };
            let c = color.map(|i| (values[i.unwrap()] * scale(i.unwrap())) as f32);
            colors.push(Vec3::from(c));
        }
    }
    mesh.normals = has_normals.then_some(normals);
    mesh.uvs = has_uv.then_some(uvs);
    mesh.colors = has_color.then_some(colors);
    Ok(())
}

fn read_faces(e: &Element, body: &mut Body, mesh: &mut PlyMesh) -> Result<(), String> {
    let list = e
        .properties
        .iter()
        .position(|p| matches!(p, Property::List(n, _, _) if n == "vertex_indices" || n == "vertex_index"))
        .ok_or("the face element needs a vertex_indices list")?;
    let candidates: Vec<(usize, String)> = e
        .properties
        .iter()
        .enumerate()
        .filter_map(|(i, p)| match p {
            Property::Scalar(n, _) => Some((i, n.clone())),
            _ => None,
        })
        .collect();
    let groups = group_attributes(&candidates);
    let first = mesh.attributes.len();
    for (name, ix) in &groups {
        mesh.attributes.push(Attribute {
            name: format!("face_{name}"),
            per_face: true,
            dim: ix.len(),
            values: Vec::new(),
        });
    }
    let mut values = vec![0f64; e.properties.len()];
    let mut polygon = Vec::new();
    for _ in 0..e.count {
        let before = mesh.triangles.len();
        for (i, p) in e.properties.iter().enumerate() {
            match p {
                Property::Scalar(_, t) => {
                    values[i] = body.value(*t)?;
                }
                Property::List(_, c, t) => {
                    let k = body.count(*c)?;
                    polygon.clear();
                    for _ in 0..k {
                        let v = body.value(*t)?;
                        if i == list {
                            if !(v >= 0.0 && v < mesh.positions.len() as f64) || v.fract() != 0.0 {
                                return Err(body.at(format!(
                                    "vertex index {v} is not one of the {} vertices (vertices must come before faces)",
                                    mesh.positions.len()
                                )));
                            }
                            polygon.push(v as u32);
                        }
                    }
                    if i == list {
                        if polygon.len() < 3 {
                            return Err(body.at(format!("a face needs at least 3 vertices, got {}", polygon.len())));
                        }
                        for j in 1..polygon.len() - 1 {
                            mesh.triangles.push([polygon[0], polygon[j], polygon[j + 1]]);
                        }
                    }
                }
            }
        }
        body.end_item()?;
        for _ in before..mesh.triangles.len() {
            for (a, (_, ix)) in mesh.attributes[first..].iter_mut().zip(&groups) {
                a.values.extend(ix.iter().map(|&i| values[i] as f32));
            }
        }
    }
    Ok(())
}

/// The data after the header, read value by value.
struct Body<'a> {
    bytes: &'a [u8],
    pos: usize,
    format: Format,
    /// ASCII: the current line and its words.
    line: usize,
    words: Vec<String>,
    word: usize,
}

impl Body<'_> {
    fn at(&self, m: String) -> String {
        match self.format {
            Format::Ascii => format!("line {}: {m}", self.line),
            _ => format!("byte {}: {m}", self.pos),
        }
    }

    fn count(&mut self, t: Scalar) -> Result<usize, String> {
        let v = self.value(t)?;
        if !(0.0..=1e6).contains(&v) || v.fract() != 0.0 {
            return Err(self.at(format!("a list length must be a count up to 1e6, got {v}")));
        }
        Ok(v as usize)
    }

    fn value(&mut self, t: Scalar) -> Result<f64, String> {
        if self.format == Format::Ascii {
            while self.word >= self.words.len() {
                if self.pos >= self.bytes.len() {
                    return Err(self.at("the file ends early".into()));
                }
                let end =
                    self.bytes[self.pos..].iter().position(|&b| b == b'\n').map_or(self.bytes.len(), |i| self.pos + i);
                let text = String::from_utf8_lossy(&self.bytes[self.pos..end]);
                self.words = text.split_ascii_whitespace().map(str::to_string).collect();
                self.word = 0;
                self.pos = (end + 1).min(self.bytes.len());
                self.line += 1;
            }
            let w = &self.words[self.word];
            self.word += 1;
            return w.parse::<f64>().map_err(|_| self.at(format!("'{w}' is not a number")));
        }
        let size = t.size();
        if self.pos + size > self.bytes.len() {
            return Err(self.at("the file ends early".into()));
        }
        let mut b = [0u8; 8];
        b[..size].copy_from_slice(&self.bytes[self.pos..self.pos + size]);
        if self.format == Format::Big {
            b[..size].reverse();
        }
        self.pos += size;
        Ok(match t {
            Scalar::I8 => b[0] as i8 as f64,
            Scalar::U8 => b[0] as f64,
            Scalar::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(b),
        })
    }

    /// ASCII items end with their line.
    fn end_item(&mut self) -> Result<(), String> {
        if self.format == Format::Ascii {
            if self.word < self.words.len() {
                return Err(self.at(format!("{} values more than the header declares", self.words.len() - self.word)));
            }
            self.words.clear();
            self.word = 0;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment a quad\nelement vertex 4\nproperty float x\nproperty float y\n\
        property float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n\
        element face 1\nproperty list uchar int vertex_indices\nend_header\n\
        0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n0 1 0 0 0 1 0 1\n4 0 1 2 3\n";

    #[test]
    fn an_ascii_quad_is_two_triangles_with_normals_and_uvs() {
        let m = parse(ASCII.as_bytes()).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.normals.as_ref().unwrap()[2], Vec3::Z);
        assert_eq!(m.uvs.as_ref().unwrap()[2], Vec2::ONE);
    }

    /// Other properties become attributes, grouped and named as Mitsuba
    /// names them; a face's values go to every triangle it is fanned into.
    #[test]
    fn vertex_and_face_properties_become_named_attributes() {
        let text = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
                    property float r\nproperty float g\nproperty float b\nproperty float temp\n\
                    element face 2\nproperty list uchar int vertex_indices\nproperty float w_0\nproperty float w_1\n\
                    property float q_x\nproperty float k_r\nproperty float k_g\nproperty float k_b\nend_header\n\
                    0 0 0 1 0 0 5\n1 0 0 0 1 0 6\n1 1 0 0 0 1 7\n0 1 0 1 1 1 8\n4 0 1 2 3 0.25 0.5 9 1 2 3\n3 0 1 2 1 2 3 4 5 6\n";
        let m = parse(text.as_bytes()).unwrap();
        let names: Vec<(&str, bool, usize)> =
            m.attributes.iter().map(|a| (a.name.as_str(), a.per_face, a.dim)).collect();
        assert_eq!(
            names,
            [
                ("vertex_color", false, 3),
                ("vertex_temp", false, 1),
                ("face_w", true, 2),
                ("face_q", true, 1),
                ("face_k_color", true, 3)
            ]
        );
        assert_eq!(m.attributes[0].color(1), Vec3::Y);
        assert_eq!(m.attributes[1].color(3), Vec3::splat(8.0));
        // The quad is two triangles with its values; then the triangle.
        assert_eq!(m.triangles.len(), 3);
        assert_eq!(m.attributes[2].values, [0.25, 0.5, 0.25, 0.5, 1.0, 2.0]);
        assert_eq!(m.attributes[3].color(2), Vec3::splat(3.0));
    }

    /// The same quad in binary, both byte orders, with a uchar colour.
    #[test]
    fn binary_files_of_either_byte_order_read_the_same() {
        for big in [false, true] {
            let mut b = format!(
                "ply\nformat binary_{}_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
                 property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\n\
                 property list uchar uint vertex_indices\nend_header\n",
                if big { "big" } else { "little" }
            )
            .into_bytes();
            let f = |v: f32| if big { v.to_be_bytes() } else { v.to_le_bytes() };
            let u = |v: u32| if big { v.to_be_bytes() } else { v.to_le_bytes() };
            for p in [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]] {
                for c in p {
                    b.extend(f(c));
                }
                b.extend([255, 0, 51]);
            }
            b.push(4);
            for i in 0..4 {
                b.extend(u(i));
            }
            let m = parse(&b).unwrap();
            assert_eq!(m.positions[2], Vec3::new(1.0, 1.0, 0.0));
            assert_eq!(m.triangles.len(), 2);
            assert!((m.colors.as_ref().unwrap()[0] - Vec3::new(1.0, 0.0, 0.2)).length() < 1e-6);
        }
    }

    #[test]
    fn mistakes_are_located() {
        let bad_index = ASCII.replace("4 0 1 2 3", "4 0 1 2 7");
        assert!(
            parse(bad_index.as_bytes()).unwrap_err().starts_with("line 20:"),
            "{}",
            parse(bad_index.as_bytes()).unwrap_err()
        );
        let short = &ASCII[..ASCII.len() - 12];
        assert!(parse(short.as_bytes()).unwrap_err().contains("ends early"));
        let bad_word = ASCII.replace("1 1 0 0 0 1 1 1", "1 x 0 0 0 1 1 1");
        assert!(parse(bad_word.as_bytes()).unwrap_err().starts_with("line 18: 'x'"));
        assert!(parse(b"plx\n").unwrap_err().contains("not a PLY"));
        let no_end = "ply\nformat ascii 1.0\nelement vertex 1\n";
        assert!(parse(no_end.as_bytes()).unwrap_err().contains("end_header"));
    }
}
