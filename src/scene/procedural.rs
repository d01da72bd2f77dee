//! Meshes made by formula: the unit icosphere, the torus and the torus knot
//! of the scene suite (`examples/suite_meshes.rs` writes them as OBJ
//! files), the benches and the tests.

use glam::Vec3;
use std::collections::HashMap;
use std::f32::consts::TAU;

/// An indexed triangle mesh with a unit normal at every vertex; faces wound
/// so that their normals point out.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub faces: Vec<[u32; 3]>,
}

impl Mesh {
    /// The faces as vertex triples.
    pub fn triangles(&self) -> Vec<[Vec3; 3]> {
        self.faces.iter().map(|f| f.map(|i| self.positions[i as usize])).collect()
    }

    /// The mesh as Wavefront OBJ text, with its vertex normals (`vn`)
    /// unless `flat`.
    pub fn to_obj(&self, flat: bool) -> String {
        use std::fmt::Write;
        let mut out = String::with_capacity(self.positions.len() * 80 + self.faces.len() * 40);
        let _ = writeln!(out, "# {} triangles, written by photonmap", self.faces.len());
        for p in &self.positions {
            let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
        }
        if !flat {
            for n in &self.normals {
                let _ = writeln!(out, "vn {} {} {}", n.x, n.y, n.z);
            }
        }
        for f in &self.faces {
            let [a, b, c] = f.map(|i| i + 1);
            if flat {
                let _ = writeln!(out, "f {a} {b} {c}");
            } else {
                let _ = writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}");
            }
        }
        out
    }

    /// The mesh moved by `f` (positions) and `g` (normals, renormalised).
    pub fn mapped(mut self, f: impl Fn(Vec3) -> Vec3, g: impl Fn(Vec3) -> Vec3) -> Mesh {
        self.positions.iter_mut().for_each(|p| *p = f(*p));
        self.normals.iter_mut().for_each(|n| *n = g(*n).normalize());
        self
    }
}

/// The unit sphere as an icosahedron whose faces are split in four
/// `subdivisions` times (20 x 4^n triangles), vertices on the sphere.
pub fn icosphere(subdivisions: u32) -> Mesh {
    let t = (1.0 + 5.0f32.sqrt()) / 2.0;
    let mut positions: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoint: HashMap<(u32, u32), u32> = HashMap::new();
        let mut mid = |a: u32, b: u32, positions: &mut Vec<Vec3>| {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                positions.push((positions[a as usize] + positions[b as usize]).normalize());
                positions.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(faces.len() * 4);
        for [a, b, c] in faces {
            let (ab, bc, ca) = (mid(a, b, &mut positions), mid(b, c, &mut positions), mid(c, a, &mut positions));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    let normals = positions.clone();
    Mesh { positions, normals, faces }
}

/// A tube of radius `radius` around a closed curve `c(s)`, s in [0, 1),
/// with `segments` rings of `sides` vertices; the rings' frames are carried
/// along the curve without twisting (parallel transport), then their last
/// twist spread back over the rings so the tube closes.
fn tube(c: impl Fn(f32) -> Vec3, radius: f32, segments: u32, sides: u32) -> Mesh {
    let tangent = |s: f32| {
        let h = 1e-4;
        (c(s + h) - c(s - h)).normalize()
    };
    let mut frames = Vec::with_capacity(segments as usize + 1);
    let t0 = tangent(0.0);
    let mut n = t0.any_orthonormal_vector();
    for i in 0..=segments {
        let t = tangent(i as f32 / segments as f32);
        n = (n - t * n.dot(t)).normalize();
        frames.push((t, n));
    }
    // The angle the transported normal is off by after one loop.
    let (t_end, n_end) = frames[segments as usize];
    let n_start = (frames[0].1 - t_end * frames[0].1.dot(t_end)).normalize();
    let twist = n_end.cross(n_start).dot(t_end).atan2(n_end.dot(n_start));
    let mut positions = Vec::with_capacity((segments * sides) as usize);
    let mut normals = Vec::with_capacity((segments * sides) as usize);
    for i in 0..segments {
        let s = i as f32 / segments as f32;
        let (t, n) = frames[i as usize];
        let b = t.cross(n);
        let extra = twist * s;
        for j in 0..sides {
            let a = TAU * j as f32 / sides as f32 + extra;
            let d = n * a.cos() + b * a.sin();
            positions.push(c(s) + radius * d);
            normals.push(d);
        }
    }
    let mut faces = Vec::with_capacity((2 * segments * sides) as usize);
    let at = |i: u32, j: u32| (i % segments) * sides + (j % sides);
    for i in 0..segments {
        for j in 0..sides {
            let (a, b, c2, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            faces.push([a, b, c2]);
            faces.push([a, c2, d]);
        }
    }
    // Wind every face with its normal pointing out of the tube.
    for f in &mut faces {
        let [a, b, c2] = f.map(|k| positions[k as usize]);
        let out: Vec3 = f.iter().map(|&k| normals[k as usize]).sum();
        if (b - a).cross(c2 - a).dot(out) < 0.0 {
            f.swap(1, 2);
        }
    }
    Mesh { positions, normals, faces }
}

/// A torus around the z axis through `center` (radii `major` > `minor`),
/// as 2 x `around` x `tube` triangles wound with outward normals: the
/// procedural mesh of the BVH benchmarks (250 x 200: 100,000 triangles).
pub fn torus(center: Vec3, major: f32, minor: f32, around: u32, tube_sides: u32) -> Mesh {
    tube(|s| center + major * Vec3::new((TAU * s).cos(), (TAU * s).sin(), 0.0), minor, around, tube_sides)
}

/// The (p, q) torus knot: a curve winding p times around the z axis and q
/// times through the hole of a torus of radii `major`, `minor`, as a tube
/// of radius `radius`.
pub fn torus_knot(p: u32, q: u32, major: f32, minor: f32, radius: f32, segments: u32, sides: u32) -> Mesh {
    let curve = |s: f32| {
        let phi = TAU * s;
        let r = major + minor * (q as f32 * phi).cos();
        Vec3::new(r * (p as f32 * phi).cos(), r * (p as f32 * phi).sin(), minor * (q as f32 * phi).sin())
    };
    tube(curve, radius, segments, sides)
}

/// A closed axis-aligned box from `lo` to `hi`, flat (its vertex normals are
/// its faces').
pub fn cuboid(lo: Vec3, hi: Vec3) -> Mesh {
    let mut m = Mesh::default();
    for axis in 0..3 {
        for side in [0.0f32, 1.0] {
            let mut n = Vec3::ZERO;
            n[axis] = if side > 0.0 { 1.0 } else { -1.0 };
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let corner = |a: f32, b: f32| {
                let mut p = Vec3::ZERO;
                p[axis] = if side > 0.0 { hi[axis] } else { lo[axis] };
                p[u] = if a > 0.0 { hi[u] } else { lo[u] };
                p[v] = if b > 0.0 { hi[v] } else { lo[v] };
                p
            };
            let base = m.positions.len() as u32;
            for (a, b) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                m.positions.push(corner(a, b));
                m.normals.push(n);
            }
            let mut faces = [[base, base + 1, base + 2], [base, base + 2, base + 3]];
            let [a, b, c] = faces[0].map(|i| m.positions[i as usize]);
            if (b - a).cross(c - a).dot(n) < 0.0 {
                faces = faces.map(|f| [f[0], f[2], f[1]]);
            }
            m.faces.extend(faces);
        }
    }
    m
}

/// The meshes of the scene suite (scenes/suite/), by file name, and
/// whether each is written flat (no `vn`). The large one is made on demand
/// (`large`): at ~80 MB it is not kept in the repository.
pub fn suite_meshes(large: bool) -> Vec<(&'static str, Mesh, bool)> {
    let mut meshes = vec![
        ("icosphere-1280.obj", icosphere(3), false),
        ("icosphere-20k.obj", icosphere(5), false),
        ("knot-16k.obj", torus_knot(2, 3, 0.8, 0.3, 0.15, 400, 20), false),
        ("block.obj", cuboid(Vec3::ZERO, Vec3::ONE), true),
    ];
    if large {
        meshes.push(("knot-1m.obj", torus_knot(2, 3, 0.8, 0.3, 0.15, 5000, 100), false));
    }
    meshes
}

/// Writes the suite's meshes into `dir`, those missing only; returns the
/// names written.
pub fn write_suite_meshes(dir: &std::path::Path, large: bool) -> std::io::Result<Vec<&'static str>> {
    std::fs::create_dir_all(dir)?;
    let mut written = Vec::new();
    for (name, mesh, flat) in suite_meshes(large) {
        let path = dir.join(name);
        if path.exists() {
            continue;
        }
        let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
        std::fs::write(&tmp, mesh.to_obj(flat))?;
        std::fs::rename(&tmp, &path)?;
        written.push(name);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed: every edge is shared by exactly two faces; outward: every
    /// face's normal agrees with its vertices'.
    fn closed_and_outward(m: &Mesh) {
        let mut edges = HashMap::new();
        for f in &m.faces {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
            let [a, b, c] = f.map(|i| m.positions[i as usize]);
            let n: Vec3 = f.iter().map(|&i| m.normals[i as usize]).sum();
            assert!((b - a).cross(c - a).dot(n) > 0.0, "inward face {f:?}");
        }
        assert!(edges.values().all(|&n| n == 2), "open mesh");
    }

    #[test]
    fn icosphere_is_a_closed_unit_sphere() {
        let m = icosphere(3);
        assert_eq!(m.faces.len(), 1280);
        assert!(m.positions.iter().all(|p| (p.length() - 1.0).abs() < 1e-6));
        closed_and_outward(&m);
    }

    #[test]
    fn torus_and_knot_are_closed_with_outward_normals() {
        let c = Vec3::new(1.0, 2.0, 3.0);
        let t = torus(c, 2.0, 0.5, 40, 30);
        assert_eq!(t.faces.len(), 2400);
        closed_and_outward(&t);
        for (p, n) in t.positions.iter().zip(&t.normals) {
            let ring = c + Vec3::new(p.x - c.x, p.y - c.y, 0.0).normalize() * 2.0;
            assert!((*p - ring).normalize().dot(*n) > 0.999);
        }
        let k = torus_knot(2, 3, 1.0, 0.4, 0.15, 300, 16);
        closed_and_outward(&k);
        assert!(k.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-5));
    }

    #[test]
    fn cuboid_is_closed_and_flat() {
        let m = cuboid(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(m.faces.len(), 12);
        let area: f32 = m.triangles().iter().map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length()).sum();
        assert!((area - 22.0).abs() < 1e-5);
        for f in &m.faces {
            let [a, b, c] = f.map(|i| m.positions[i as usize]);
            assert!((b - a).cross(c - a).normalize().dot(m.normals[f[0] as usize]) > 0.999);
        }
    }

    #[test]
    fn obj_text_round_trips_through_the_loader() {
        let m = icosphere(1);
        let dir = std::env::temp_dir().join(format!("photonmap-obj-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("sphere.obj");
        std::fs::write(&path, m.to_obj(false)).unwrap();
        let read = crate::scene::mesh::load_obj(&path).unwrap();
        assert_eq!(read.triangles.len(), 80);
        let normals = read.normals.expect("vn read");
        for (t, n) in read.triangles.iter().zip(&normals) {
            for k in 0..3 {
                assert!((t[k].normalize() - n[k]).length() < 1e-5);
            }
        }
        std::fs::write(&path, m.to_obj(true)).unwrap();
        assert!(crate::scene::mesh::load_obj(&path).unwrap().normals.is_none());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
