//! `<shape>` plugins as primitives, each placed by its `to_world` (and an
//! instance's), with its BSDF and, for an area emitter, a light per
//! triangle. Mitsuba's shapes in their own frames (src/shapes/*.cpp):
//! `rectangle` is [-1, 1]^2 at z = 0 facing +z, `cube` is [-1, 1]^3,
//! `disk` the unit disk facing +z (an ellipse under an uneven scale),
//! `sphere` a `center` and `radius` (an ellipsoid under an uneven scale),
//! `cylinder` an open tube of `radius` from `p0` to `p1`, its normals away
//! from the axis, `sdfgrid` a signed distance grid over [0, 1]^3 read from
//! a `.vol` file (crate::shape::SdfGrid).
//!
//! Meshes keep their vertex normals; a mesh without them gets
//! angle-weighted vertex normals (Thürmer and Wüthrich 1998), as Mitsuba
//! computes them, unless `face_normals` is set. A transform that mirrors
//! reverses the winding, so that the front stays where the normals point.

use super::props::{Plugin, Value};
use super::spectrum::Use;
use super::Builder;
use crate::light::{AreaLight, Emitting};
use crate::math::Color;
use crate::scene::file::SceneError;
use crate::scene::mesh::load_obj;
use crate::scene::ply::load_ply;
use crate::scene::serialized::load_serialized;
use crate::scene::Prim;
use crate::shape::{Cylinder, Disk, Ellipse, Ellipsoid, Normals, SdfGrid, Shape, Sphere, Triangle};
use crate::texture::SurfaceUv;
use glam::{Affine3A, DAffine3, DVec3, Vec2, Vec3};
use std::collections::HashMap;

/// Triangles in their own space with their corners' normals, if smooth,
/// texture coordinates, if any, and attributes (name, corner values).
struct Tris {
    tris: Vec<[Vec3; 3]>,
    normals: Option<Vec<[Vec3; 3]>>,
    uvs: Option<Vec<[Vec2; 3]>>,
    attributes: Vec<(String, Vec<[Color; 3]>)>,
}

impl Tris {
    fn plain(tris: Vec<[Vec3; 3]>) -> Self {
        Tris { tris, normals: None, uvs: None, attributes: Vec::new() }
    }
}

impl Builder<'_> {
    pub(super) fn shape(&mut self, p: &Plugin, outer: DAffine3) -> Result<(), SceneError> {
        match p.kind {
            // Built where an instance names it.
            "shapegroup" => {
                let children = p.objects("shape")?;
                p.finish("nested <shape>s")?;
                if let Some(c) = children.iter().find(|c| c.kind == "shapegroup" || c.kind == "instance") {
                    return Err(c.refuse("a shapegroup cannot hold another shapegroup or an instance"));
                }
                return Ok(());
            }
            "instance" => {
                let group = p.object("shape")?.ok_or_else(|| p.refuse("an instance needs a <ref> to a shapegroup"))?;
                let to_world = p.transform("to_world")?.unwrap_or(DAffine3::IDENTITY);
                p.finish("a shapegroup reference, to_world")?;
                if group.kind != "shapegroup" {
                    return Err(group.refuse("an instance must refer to a shapegroup"));
                }
                let m = outer * to_world;
                for child in group.objects("shape")? {
                    self.shape(&child, m)?;
                }
                return Ok(());
            }
            _ => {}
        }
        let interface = self.interface(p)?;
        let (prims, lights) = (self.prims.len(), self.lights.len());
        let bsdf = p.object("bsdf")?;
        let material = self.material(bsdf.as_ref())?;
        let emitter = p.object("emitter")?;
        let mut image = None;
        let radiance = match &emitter {
            None => None,
            Some(e) if e.kind == "area" => {
                let r = match e.value("radiance", Use::Emission)? {
                    None => Color::ONE,
                    Some(Value::Color(c)) => c,
                    Some(Value::Texture(t)) => {
                        let texture = self.emitter_texture(&t)?;
                        if texture.min() < 0.0 {
                            return Err(t.refuse("an emitted radiance must not be negative"));
                        }
                        image = Some(texture);
                        Color::ONE
                    }
                };
                e.finish("radiance")?;
                if r.min_element() < 0.0 {
                    return Err(e.fail(e.loc(), "radiance", "must not be negative"));
                }
                Some(r)
            }
            Some(e) => return Err(e.refuse(format!("a shape's emitter must be 'area', got '{}'", e.kind))),
        };
        let to_world = outer * p.transform("to_world")?.unwrap_or(DAffine3::IDENTITY);
        let flip = p.boolean("flip_normals", false)?;
        if to_world.matrix3.determinant() == 0.0 {
            return Err(p.fail(p.loc(), "to_world", "the transform is singular"));
        }
        let object = self.new_object();
        self.origins.objects.resize(object as usize, super::place(p));
        self.origins.objects.push(super::place(p));
        let mut uv = None;
        let mesh = match p.kind {
            "obj" | "ply" | "serialized" => {
                let face_normals = p.boolean("face_normals", false)?;
                let (name, loc) = p.string("filename")?.ok_or_else(|| p.refuse("needs a filename"))?;
                let path = self.resolve(&name, &loc)?;
                // Mitsuba flips an OBJ's v by default, a PLY's only when asked.
                let flip_v = p.boolean("flip_tex_coords", p.kind == "obj")?;
                let (tris, normals, shared, uvs, attributes) = if p.kind == "obj" {
                    let m = load_obj(&path).map_err(|e| p.fail(&loc, "filename", e))?;
                    (m.triangles, m.normals, None, m.uvs, Vec::new())
                } else {
                    let m = if p.kind == "ply" {
                        load_ply(&path).map_err(|e| p.fail(&loc, "filename", e))?
                    } else {
                        // The file's own face-normal flag is not read: Mitsuba 3
                        // takes the parameter alone (serialized.cpp, load_legacy).
                        let index = p.integer("shape_index")?.unwrap_or(0);
                        let index = u32::try_from(index)
                            .map_err(|_| p.fail(p.loc(), "shape_index", format!("must be 0 or more, got {index}")))?;
                        load_serialized(&path, index).map_err(|e| p.fail(&loc, "filename", e))?.mesh
                    };
                    let tris: Vec<[Vec3; 3]> = m.triangles.iter().map(|t| t.map(|i| m.positions[i as usize])).collect();
                    let normals = m.normals.as_ref().map(|n| m.triangles.iter().map(|t| t.map(|i| n[i as usize])).collect());
                    let uvs = m.uvs.as_ref().map(|uv| m.triangles.iter().map(|t| t.map(|i| uv[i as usize])).collect());
                    let attributes = m
                        .attributes
                        .iter()
                        .map(|a| {
                            let per_tri = (0..m.triangles.len())
                                .map(|f| {
                                    if a.per_face {
                                        [a.color(f); 3]
                                    } else {
                                        m.triangles[f].map(|i| a.color(i as usize))
                                    }
                                })
                                .collect();
                            (a.name.clone(), per_tri)
                        })
                        .collect();
                    (tris, normals, Some(m.triangles.clone()), uvs, attributes)
                };
                let uvs = uvs.map(|uvs: Vec<[Vec2; 3]>| {
                    if flip_v {
                        uvs.into_iter().map(|t| t.map(|uv| Vec2::new(uv.x, 1.0 - uv.y))).collect()
                    } else {
                        uvs
                    }
                });
                let normals = match (face_normals, normals) {
                    (true, _) => None,
                    (false, Some(n)) => Some(n),
                    (false, None) => Some(smooth_normals(&tris, shared.as_deref())),
                };
                Mesh::Tris(Tris { tris, normals, uvs, attributes })
            }
            "rectangle" => {
                // Mitsuba's coordinates: (x + 1) / 2, (y + 1) / 2.
                let uv = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]].map(Vec2::from_array);
                let c = uv.map(|t| (2.0 * t - 1.0).extend(0.0));
                Mesh::Tris(Tris {
                    uvs: Some(vec![[uv[0], uv[1], uv[2]], [uv[0], uv[2], uv[3]]]),
                    ..Tris::plain(vec![[c[0], c[1], c[2]], [c[0], c[2], c[3]]])
                })
            }
            "cube" => {
                let (tris, uvs) = cube();
                Mesh::Tris(Tris { uvs: Some(uvs), ..Tris::plain(tris) })
            }
            "sphere" => {
                let center = p.point("center")?.unwrap_or(DVec3::ZERO);
                let radius = p.float_in("radius", 1.0, 0.0, 1e15)?;
                let m = to_world * DAffine3::from_translation(center) * DAffine3::from_scale(DVec3::splat(radius));
                self.frames.push(affine(&m.inverse()));
                uv = Some(SurfaceUv::Sphere(self.frames.len() as u32 - 1));
                let ellipsoid =
                    || Ellipsoid::new(affine(&m)).ok_or_else(|| p.fail(p.loc(), "to_world", "the transform is singular"));
                Mesh::Analytic(match similarity(&m) {
                    Some(s) if !flip => Shape::Sphere(Sphere { center: m.translation.as_vec3(), radius: s as f32 }),
                    // Inward normals: the ellipsoid holds the flag.
                    _ if flip => Shape::Ellipsoid(ellipsoid()?.flipped()),
                    _ => Shape::Ellipsoid(ellipsoid()?),
                })
            }
            "cylinder" => {
                let p0 = p.point("p0")?.unwrap_or(DVec3::ZERO);
                let p1 = p.point("p1")?.unwrap_or(DVec3::Z);
                let radius = p.float_in("radius", 1.0, 0.0, 1e15)?;
                let m = cylinder_frame(p0, p1, radius).map(|f| to_world * f).ok_or_else(|| {
                    p.fail(p.loc(), "p1", "the cylinder needs p1 apart from p0 and a radius above 0")
                })?;
                if m.matrix3.determinant() < 0.0 {
                    return Err(p.fail(p.loc(), "to_world", "a mirroring transform is not supported for a cylinder"));
                }
                let [x, y, z] = [m.matrix3.x_axis, m.matrix3.y_axis, m.matrix3.z_axis];
                let tol = 1e-6 * x.length();
                if (x.length() - y.length()).abs() > tol || x.dot(y).abs() > tol * x.length() {
                    return Err(p.fail(p.loc(), "to_world", "a cylinder stretched into an elliptic one is not supported"));
                }
                if x.dot(z).abs() + y.dot(z).abs() > tol * z.length() {
                    return Err(p.fail(p.loc(), "to_world", "a sheared cylinder is not supported"));
                }
                let (a, b) = (m.translation.as_vec3(), m.transform_point3(DVec3::Z).as_vec3());
                self.frames.push(affine(&m.inverse()));
                uv = Some(SurfaceUv::Cylinder(self.frames.len() as u32 - 1));
                let c = Cylinder::new(a, b, x.length() as f32, flip)
                    .ok_or_else(|| p.fail(p.loc(), "to_world", "the cylinder is empty or not finite in world space"))?;
                Mesh::Analytic(Shape::Cylinder(c))
            }
            "disk" => {
                self.frames.push(affine(&to_world.inverse()));
                uv = Some(SurfaceUv::Disk(self.frames.len() as u32 - 1));
                // Mitsuba's normal is to_world's image of +z as a normal:
                // for a similarity s R, R's z column.
                let normal = |s: f64| match super::unit(to_world.matrix3.z_axis / s) {
                    Some(n) if flip => -n,
                    Some(n) => n,
                    None => Vec3::Z,
                };
                Mesh::Analytic(match similarity(&to_world) {
                    Some(s) => Shape::Disk(Disk {
                        center: to_world.translation.as_vec3(),
                        normal: normal(s),
                        radius: s as f32,
                    }),
                    None => {
                        let e = Ellipse::new(&to_world)
                            .ok_or_else(|| p.fail(p.loc(), "to_world", "the transform is singular"))?;
                        Shape::Ellipse(if flip { e.flipped() } else { e })
                    }
                })
            }
            "sdfgrid" => {
                let (name, loc) = p.string("filename")?.ok_or_else(|| p.refuse("an sdfgrid needs a filename"))?;
                let normals = match p.string("normals")? {
                    None => Normals::Smooth,
                    Some((n, _)) if n == "smooth" => Normals::Smooth,
                    Some((n, _)) if n == "analytic" => Normals::Analytic,
                    Some((n, at)) => return Err(p.fail(&at, "normals", format!("'{n}' (smooth or analytic)"))),
                };
                if flip {
                    return Err(p.fail(p.loc(), "flip_normals", "is not a parameter of Mitsuba's sdfgrid"));
                }
                if emitter.is_some() {
                    return Err(p.refuse("an sdfgrid cannot be an area emitter (as in Mitsuba)"));
                }
                let path = self.resolve(&name, &loc)?;
                let vol = crate::scene::vol::load_vol(&path).map_err(|e| p.fail(&loc, "filename", e))?;
                if vol.channels != 1 {
                    return Err(p.fail(&loc, "filename", format!("the grid has {} channels, an sdfgrid 1", vol.channels)));
                }
                let grid = SdfGrid::new(vol.size, vol.data, to_world, normals).map_err(|e| p.fail(&loc, "filename", e))?;
                Mesh::Analytic(Shape::SdfGrid(std::sync::Arc::new(grid)))
            }
            k => {
                return Err(p.refuse(format!(
                    "the '{k}' shape is not supported yet (obj, ply, serialized, rectangle, cube, sphere, cylinder, disk, sdfgrid, shapegroup, instance are)"
                )))
            }
        };
        p.finish("filename, shape_index, face_normals, flip_normals, flip_tex_coords, to_world, center, radius, p0, p1, normals, bsdf, emitter, interior, exterior")?;
        match mesh {
            Mesh::Analytic(shape) => match (radiance, shape) {
                (None, shape) => {
                    self.surface(self.prims.len(), uv.unwrap_or(SurfaceUv::Barycentric));
                    self.prims.push(Prim { shape, material, object })
                }
                (Some(_), Shape::Disk(_)) if image.is_some() => {
                    return Err(p.refuse(
                        "an emitting disk with a radiance texture is not supported yet (meshes and rectangles are)",
                    ))
                }
                (Some(radiance), Shape::Disk(d)) => {
                    self.origins.lights.push(super::place(p));
                    self.lights.push(AreaLight::unplaced(Emitting::Disk(d), radiance, self.reflecting(material)))
                }
                (Some(_), _) => {
                    return Err(p.refuse(format!(
                        "an emitting {} is not supported yet (emitting meshes, rectangles and disks are)",
                        p.kind
                    )))
                }
            },
            Mesh::Tris(t) => {
                let emits = radiance.map(|r| (r, image, super::place(p)));
                self.push_triangles(t, &to_world, flip, material, object, emits)
            }
        }
        self.bind_media(interface, prims, lights);
        Ok(())
    }

    fn push_triangles(
        &mut self,
        mesh: Tris,
        to_world: &DAffine3,
        flip: bool,
        material: u32,
        object: u32,
        emits: Option<(Color, Option<std::sync::Arc<crate::texture::Texture>>, crate::scene::file::Place)>,
    ) {
        let normal_map = to_world.matrix3.inverse().transpose();
        // A mirroring transform and flip_normals each turn the surface over.
        let reverse = (to_world.matrix3.determinant() < 0.0) != flip;
        let sign = if flip { -1.0 } else { 1.0 };
        for (i, tri) in mesh.tris.iter().enumerate() {
            let mut v = tri.map(|p| to_world.transform_point3(p.as_dvec3()).as_vec3());
            let mut n = mesh
                .normals
                .as_ref()
                .map(|ns| ns[i].map(|n| super::unit(normal_map * n.as_dvec3() * sign).unwrap_or(Vec3::ZERO)));
            if reverse {
                v.swap(1, 2);
                if let Some(n) = &mut n {
                    n.swap(1, 2);
                }
            }
            // Without coordinates of its own a triangle's are its barycentrics.
            let mut uv = mesh.uvs.as_ref().map_or([Vec2::ZERO, Vec2::X, Vec2::Y], |uvs| uvs[i]);
            if reverse {
                uv.swap(1, 2);
            }
            let mut t = Triangle::new(v[0], v[1], v[2]);
            if !(t.area() > 0.0) {
                continue;
            }
            if let Some((radiance, image, place)) = &emits {
                self.origins.lights.push(place.clone());
                let radiance = *radiance;
                if let Some(texture) = image {
                    let pattern = crate::light::AreaPattern { texture: (**texture).clone(), uv };
                    self.light_patterns.resize(self.lights.len(), None);
                    self.light_patterns.push(Some(std::sync::Arc::new(pattern)));
                }
                self.lights.push(AreaLight::unplaced(Emitting::Triangle(t), radiance, self.reflecting(material)));
                continue;
            }
            if let Some(n) = n.filter(|n| n.iter().all(|c| c.length_squared() > 0.0)) {
                // Shading normals on the winding's side, as the renderer expects.
                let n = if (n[0] + n[1] + n[2]).dot(t.normal) < 0.0 { n.map(|c| -c) } else { n };
                if n.iter().any(|c| (*c - t.normal).length_squared() > 1e-12) {
                    t.shading = self.shading_normals.len() as u32;
                    self.shading_normals.push(n);
                }
            }
            let prim = self.prims.len();
            self.surface(prim, SurfaceUv::Triangle(uv));
            if !mesh.attributes.is_empty() {
                self.attributes(prim, |name| {
                    let (_, values) = mesh.attributes.iter().find(|(n, _)| n == name)?;
                    let mut c = values[i];
                    if reverse {
                        c.swap(1, 2);
                    }
                    Some(c)
                });
            }
            self.prims.push(Prim { shape: Shape::Triangle(t), material, object });
        }
    }
}

impl Builder<'_> {
    /// An emitter's material, or `None` where it is black (a diffuse BSDF
    /// of reflectance 0, what the export gives a pure emitter): the pure
    /// emitter, which absorbs what reaches it without storing photons.
    fn reflecting(&self, material: u32) -> Option<u32> {
        let plain = self.textured.get(material as usize).is_none_or(Option::is_none);
        let black = matches!(self.materials[material as usize], crate::material::Material::Lambertian { rho } if rho == Color::ZERO);
        (!(plain && black)).then_some(material)
    }
}

enum Mesh {
    Tris(Tris),
    Analytic(Shape),
}

/// The uniform scale of a transform made of rotations, translations and
/// uniform scales (`None` if it shears or scales unevenly).
fn similarity(m: &DAffine3) -> Option<f64> {
    let [x, y, z] = [m.matrix3.x_axis, m.matrix3.y_axis, m.matrix3.z_axis];
    let s = x.length();
    let tol = 1e-6 * s;
    let fits = (y.length() - s).abs() <= tol
        && (z.length() - s).abs() <= tol
        && x.dot(y).abs() <= tol * s
        && x.dot(z).abs() <= tol * s
        && y.dot(z).abs() <= tol * s;
    (fits && s > 0.0).then_some(s)
}

/// Mitsuba's cylinder frame (cylinder.cpp): the unit-radius, unit-length
/// tube along z carried to the segment p0-p1 with the given radius; `None`
/// for an empty segment or radius. Its x axis is where the texture's u
/// starts, as Mitsuba's frame of the axis places it.
fn cylinder_frame(p0: DVec3, p1: DVec3, radius: f64) -> Option<DAffine3> {
    let d = p1 - p0;
    let length = d.length();
    let axis = d.try_normalize().filter(|_| radius > 0.0 && length.is_finite())?;
    let (x, y) = coordinate_system(axis);
    Some(DAffine3::from_cols(x * radius, y * radius, d, p0))
}

/// The tangents Mitsuba's `coordinate_system` gives a unit normal (Duff
/// et al. 2017, "Building an orthonormal basis, revisited").
fn coordinate_system(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), DVec3::new(b, sign + n.y * n.y * a, -n.y))
}

fn affine(m: &DAffine3) -> Affine3A {
    Affine3A::from_mat3_translation(m.matrix3.as_mat3(), m.translation.as_vec3())
}

/// [-1, 1]^3 as 12 outward-wound triangles with Mitsuba's texture
/// coordinates (cube.cpp): each face maps onto [0, 1]^2, its corners
/// numbered as Mitsuba numbers them (corner c at (+-1, +-1, +-1), bit k
/// of c the sign of axis k).
fn cube() -> (Vec<[Vec3; 3]>, Vec<[Vec2; 3]>) {
    const CORNERS: [u32; 24] = [1, 5, 4, 0, 3, 2, 6, 7, 1, 3, 7, 5, 5, 7, 6, 4, 4, 6, 2, 0, 3, 1, 0, 2];
    let uv = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]].map(Vec2::from_array);
    let corner = |c: u32| {
        Vec3::new([-1.0, 1.0][(c & 1) as usize], [-1.0, 1.0][(c >> 1 & 1) as usize], [-1.0, 1.0][(c >> 2 & 1) as usize])
    };
    let (mut tris, mut uvs) = (Vec::new(), Vec::new());
    for side in 0..6 {
        let v = |k: usize| corner(CORNERS[4 * side + k]);
        for [a, b, c] in [[0, 1, 2], [3, 0, 2]] {
            tris.push([v(a), v(b), v(c)]);
            uvs.push([uv[a], uv[b], uv[c]]);
        }
    }
    (tris, uvs)
}

/// Angle-weighted vertex normals, shared by the corners of one vertex:
/// the vertex indices where a file has them, else equal positions.
fn smooth_normals(tris: &[[Vec3; 3]], indices: Option<&[[u32; 3]]>) -> Vec<[Vec3; 3]> {
    let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
    let corner_ids: Vec<[u32; 3]> = match indices {
        Some(ix) => ix.to_vec(),
        None => tris
            .iter()
            .map(|t| {
                t.map(|p| {
                    let n = ids.len() as u32;
                    *ids.entry(p.to_array().map(f32::to_bits)).or_insert(n)
                })
            })
            .collect(),
    };
    let count = corner_ids.iter().flatten().max().map_or(0, |m| *m as usize + 1);
    let mut acc = vec![Vec3::ZERO; count];
    for (t, ids) in tris.iter().zip(&corner_ids) {
        let Some(n) = (t[1] - t[0]).cross(t[2] - t[0]).try_normalize() else { continue };
        for k in 0..3 {
            let a = (t[(k + 1) % 3] - t[k]).normalize_or_zero();
            let b = (t[(k + 2) % 3] - t[k]).normalize_or_zero();
            acc[ids[k] as usize] += n * a.dot(b).clamp(-1.0, 1.0).acos();
        }
    }
    corner_ids.iter().map(|ids| ids.map(|i| acc[i as usize].normalize_or_zero())).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cube_faces_outwards_and_closes() {
        let (c, _) = cube();
        assert_eq!(c.len(), 12);
        let mut area = 0.0;
        for t in &c {
            let n = (t[1] - t[0]).cross(t[2] - t[0]);
            let centre = (t[0] + t[1] + t[2]) / 3.0;
            assert!(n.dot(centre) > 0.0, "{t:?} faces inwards");
            area += 0.5 * n.length();
        }
        assert!((area - 24.0).abs() < 1e-5);
    }

    /// Each face of the cube maps onto the unit square: its corners take
    /// the four corners of [0, 1]^2, and u and v run along its edges.
    #[test]
    fn the_cubes_faces_each_map_onto_the_unit_square() {
        let (tris, uvs) = cube();
        for face in 0..6 {
            let (t, uv) = (&tris[2 * face..2 * face + 2], &uvs[2 * face..2 * face + 2]);
            let mut corners: Vec<[i32; 2]> = uv.iter().flatten().map(|c| [c.x as i32, c.y as i32]).collect();
            corners.sort();
            corners.dedup();
            assert_eq!(corners, [[0, 0], [0, 1], [1, 0], [1, 1]], "face {face}");
            // The same uv is the same point in both triangles.
            for (p, c) in t[0].iter().zip(&uv[0]) {
                for (q, d) in t[1].iter().zip(&uv[1]) {
                    assert_eq!(p == q, c == d, "face {face}");
                }
            }
        }
    }

    /// A flat fan gets the plane's normal at every corner; a corner of a
    /// cube gets the diagonal.
    #[test]
    fn smooth_normals_weigh_by_angle() {
        let quad = [[Vec3::ZERO, Vec3::X, Vec3::ONE.with_z(0.0)], [Vec3::ZERO, Vec3::ONE.with_z(0.0), Vec3::Y]];
        for n in smooth_normals(&quad, None).iter().flatten() {
            assert!((*n - Vec3::Z).length() < 1e-6);
        }
        let (c, _) = cube();
        let n = smooth_normals(&c, None);
        let corner = Vec3::ONE.normalize();
        let found = c.iter().zip(&n).flat_map(|(t, n)| t.iter().zip(n)).find(|(p, _)| **p == Vec3::ONE).unwrap();
        assert!((*found.1 - corner).length() < 1e-5, "{:?}", found.1);
    }

    #[test]
    fn similarities_are_told_from_stretches() {
        let rot = DAffine3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        assert!((similarity(&(DAffine3::from_scale(DVec3::splat(2.5)) * rot)).unwrap() - 2.5).abs() < 1e-9);
        assert!(similarity(&DAffine3::from_scale(DVec3::new(1.0, 2.0, 1.0))).is_none());
    }
}
