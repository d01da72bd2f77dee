//! `[[shapes]]`: geometry, each of a named material or emissive.

use super::build::{at, At, Builder};
use super::defs::{Entry, V3};
use super::SceneError;
use crate::light::{AreaLight, Emitting};
use crate::math::Color;
use crate::scene::mesh::load_obj;
use crate::scene::{tncg15_room, Prim};
use crate::shape::{tetrahedron, Disk, Ellipsoid, Shape, Sphere, Triangle};
use crate::texture::SurfaceUv;
use glam::{Affine3A, Vec3};
use serde::Deserialize;
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

/// `type = "triangle"` and `"quad"`: three or four corners (a quad's in
/// one plane), of a material, or emissive (`emission`), or both.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Polygon {
    material: Option<Spanned<String>>,
    emission: Option<Spanned<V3>>,
    vertices: Spanned<Vec<V3>>,
}

/// `type = "mesh"`: an OBJ or PLY file's triangles, transformed.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Mesh {
    material: Option<Spanned<String>>,
    emission: Option<Spanned<V3>>,
    file: Spanned<String>,
    face_normals: Option<Spanned<bool>>,
    transform: Option<Vec<Spanned<StepDef>>>,
}

/// `type = "sphere"`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereDef {
    material: Spanned<String>,
    center: Spanned<V3>,
    radius: Spanned<f32>,
}

/// `type = "ellipsoid"`: the unit sphere transformed (CS475's).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EllipsoidDef {
    material: Spanned<String>,
    transform: Option<Vec<Spanned<StepDef>>>,
}

/// `type = "tetrahedron"`: four corners.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TetrahedronDef {
    material: Spanned<String>,
    vertices: Spanned<Vec<V3>>,
}

/// `type = "disk"`: a flat disk.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DiskDef {
    material: Spanned<String>,
    center: Spanned<V3>,
    normal: Spanned<V3>,
    radius: Spanned<f32>,
}

/// `type = "room"`: the TNCG15 hexagonal room.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RoomDef {
    floor: Spanned<String>,
    ceiling: Spanned<String>,
    walls: Spanned<Vec<Spanned<String>>>,
}

/// Per triangle, the vertex normals and texture coordinates at its corners.
type Corners<'c> = (Option<&'c [[Vec3; 3]]>, Option<&'c [[glam::Vec2; 3]]>);

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepDef {
    pub translate: Option<Spanned<V3>>,
    pub rotate: Option<Spanned<RotateDef>>,
    pub scale: Option<Spanned<V3>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotateDef {
    pub axis: Spanned<V3>,
    pub degrees: Spanned<f32>,
}

impl Builder<'_> {
    /// The steps of the `transform` at `prefix` (e.g. `shapes[2].transform`).
    pub(super) fn transform(
        &self,
        prefix: &str,
        steps: &Option<Vec<Spanned<StepDef>>>,
    ) -> Result<Affine3A, SceneError> {
        let mut m = Affine3A::IDENTITY;
        for (j, step) in steps.iter().flatten().enumerate() {
            let field = format!("{prefix}[{j}]");
            let s = step.get_ref();
            let set = [s.translate.is_some(), s.rotate.is_some(), s.scale.is_some()];
            if set.iter().filter(|&&b| b).count() != 1 {
                return self.fail(step.span(), &field, "a step is exactly one of translate, rotate or scale");
            }
            let next = if let Some(t) = &s.translate {
                Affine3A::from_translation(self.finite(&at(t, format!("{field}.translate")))?)
            } else if let Some(r) = &s.rotate {
                let r = r.get_ref();
                let axis = self.direction(&at(&r.axis, format!("{field}.rotate.axis")))?;
                let deg = self.number(&at(&r.degrees, format!("{field}.rotate.degrees")), -1e6, 1e6, false)?;
                Affine3A::from_axis_angle(axis, deg.to_radians())
            } else if let Some(sc) = &s.scale {
                let v = at(sc, format!("{field}.scale"));
                let k = self.finite(&v)?;
                if k.abs().min_element() == 0.0 {
                    return self.fail(v.span, &v.field, format!("a scale must not be zero, got {k}"));
                }
                Affine3A::from_scale(k)
            } else {
                unreachable!("exactly one step kind is set")
            };
            // Steps apply in the order listed: the first acts first.
            m = next * m;
        }
        Ok(m)
    }

    pub(super) fn shape(&mut self, i: usize, mut entry: Entry) -> Result<(), SceneError> {
        let f = |n: &str| format!("shapes[{i}].{n}");
        let kind = entry.kind.get_ref().clone();
        let kind_span = entry.kind.span();
        let object = i as u32;
        match kind.as_str() {
            "triangle" | "quad" => {
                let d: Polygon = entry.read(&self.src)?;
                let emission = self.emission(i, &d.emission)?;
                let n = if kind == "triangle" { 3 } else { 4 };
                let v = self.vertices(&d.vertices, f("vertices"), n)?;
                let triangles = if n == 3 {
                    vec![Triangle::new(v[0], v[1], v[2])]
                } else {
                    // Planar: the fourth corner on the plane of the first three.
                    let normal = (v[1] - v[0]).cross(v[2] - v[0]);
                    let size = (v[2] - v[0]).length().max((v[3] - v[1]).length());
                    if !((v[3] - v[0]).dot(normal.normalize_or_zero()).abs() <= 1e-4 * size) {
                        let span = d.vertices.span();
                        return self.fail(span, &f("vertices"), "the four corners of a quad must lie in one plane");
                    }
                    vec![Triangle::new(v[0], v[1], v[2]), Triangle::new(v[0], v[2], v[3])]
                };
                self.triangles(i, &d.material, emission, &triangles, (None, None), d.vertices.span())?;
            }
            "mesh" => {
                let d: Mesh = entry.read(&self.src)?;
                let emission = self.emission(i, &d.emission)?;
                let file = at(&d.file, f("file"));
                let m = self.transform(&f("transform"), &d.transform)?;
                let obj_path = self.src.path.parent().unwrap_or(Path::new(".")).join(file.value);
                let ply = obj_path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ply"));
                let (mesh, attributes) =
                    if ply { ply_mesh(&obj_path) } else { load_obj(&obj_path).map(|m| (m, Vec::new())) }
                        .map_err(|e| self.src.error(file.span.clone(), file.field.clone(), e))?;
                self.meshes.push(obj_path.clone());
                let triangles: Vec<Triangle> = mesh
                    .triangles
                    .iter()
                    .map(|[a, b, c]| {
                        Triangle::new(m.transform_point3(*a), m.transform_point3(*b), m.transform_point3(*c))
                    })
                    .collect();
                // Normals go through the inverse transpose (a mirroring
                // transform flips the winding and the normals alike).
                let flat = d.face_normals.as_ref().is_some_and(|f| *f.get_ref()) || emission.is_some();
                let normal_map = m.matrix3.inverse().transpose();
                let normals = mesh.normals.filter(|_| !flat).map(|normals| {
                    normals
                        .iter()
                        .map(|n| {
                            n.map(|v| {
                                Vec3::from(normal_map * glam::Vec3A::from(v)).try_normalize().unwrap_or(Vec3::ZERO)
                            })
                        })
                        .collect::<Vec<_>>()
                });
                // Texture coordinates as Mitsuba reads an OBJ's: v from the
                // bottom of the image (obj.cpp's flip_tex_coords); a PLY's
                // as they are.
                let flip = |uv: glam::Vec2| if ply { uv } else { glam::Vec2::new(uv.x, 1.0 - uv.y) };
                let uvs = mesh.uvs.map(|uvs| uvs.iter().map(|t| t.map(flip)).collect::<Vec<_>>());
                let corners = (normals.as_deref(), uvs.as_deref());
                let first = self.prims.len();
                let kept = self.triangles(i, &d.material, emission, &triangles, corners, kind_span)?;
                if emission.is_none() {
                    for (name, values) in attributes {
                        let prims = kept.iter().enumerate().map(|(k, &j)| (first + k, values[j]));
                        self.mesh_attributes.entry(name).or_default().extend(prims);
                    }
                }
            }
            "sphere" => {
                let d: SphereDef = self.read_shape(&mut entry)?;
                let material = self.material_ref(&d.material, f("material"))?;
                let center = self.finite(&at(&d.center, f("center")))?;
                let radius = self.number(&at(&d.radius, f("radius")), 0.0, f32::INFINITY, true)?;
                let frame = super::texture::sphere_frame(center, radius);
                self.surface(self.prims.len(), frame, SurfaceUv::Sphere);
                self.prims.push(Prim { shape: Shape::Sphere(Sphere { center, radius }), material, object });
            }
            "ellipsoid" => {
                let d: EllipsoidDef = self.read_shape(&mut entry)?;
                let material = self.material_ref(&d.material, f("material"))?;
                let m = self.transform(&f("transform"), &d.transform)?;
                let e = Ellipsoid::new(m)
                    .ok_or_else(|| self.src.error(kind_span.clone(), f("transform"), "the transform is singular"))?;
                // Textured as Mitsuba's sphere under the same transform.
                self.surface(self.prims.len(), super::texture::ellipsoid_frame(&e), SurfaceUv::Sphere);
                self.prims.push(Prim { shape: Shape::Ellipsoid(e), material, object });
            }
            "tetrahedron" => {
                let d: TetrahedronDef = self.read_shape(&mut entry)?;
                let material = self.material_ref(&d.material, f("material"))?;
                let v = self.vertices(&d.vertices, f("vertices"), 4)?;
                for t in tetrahedron(v[0], v[1], v[2], v[3]) {
                    self.prims.push(Prim { shape: Shape::Triangle(t), material, object });
                }
            }
            "disk" => {
                let d: DiskDef = self.read_shape(&mut entry)?;
                let material = self.material_ref(&d.material, f("material"))?;
                let center = self.finite(&at(&d.center, f("center")))?;
                let normal = self.direction(&at(&d.normal, f("normal")))?;
                let radius = self.number(&at(&d.radius, f("radius")), 0.0, f32::INFINITY, true)?;
                let disk = Disk { center, normal, radius };
                self.surface(self.prims.len(), super::texture::disk_frame(&disk), SurfaceUv::Disk);
                self.prims.push(Prim { shape: Shape::Disk(disk), material, object });
            }
            "room" => {
                let d: RoomDef = self.read_shape(&mut entry)?;
                let floor = self.material_ref(&d.floor, f("floor"))?;
                let ceiling = self.material_ref(&d.ceiling, f("ceiling"))?;
                if d.walls.get_ref().len() != 6 {
                    let n = d.walls.get_ref().len();
                    return self.fail(d.walls.span(), &f("walls"), format!("needs 6 wall materials, got {n}"));
                }
                let mut walls = [0u32; 6];
                for (w, name) in walls.iter_mut().zip(d.walls.get_ref()) {
                    *w = self.material_ref(name, f("walls"))?;
                }
                self.prims.extend(tncg15_room(floor, ceiling, walls, object));
            }
            other => {
                return self.fail(
                    kind_span,
                    &f("type"),
                    format!(
                    "unknown shape type \"{other}\" (triangle, quad, mesh, sphere, ellipsoid, tetrahedron, disk, room)"
                ),
                )
            }
        }
        Ok(())
    }

    /// A shape that cannot emit: `emission` is refused with what can.
    fn read_shape<T: serde::de::DeserializeOwned>(&self, entry: &mut Entry) -> Result<T, SceneError> {
        entry.read(&self.src).map_err(|mut e| {
            if e.field.ends_with(".emission") && e.message.starts_with("unknown field") {
                e.message = "only triangles and meshes can be made emissive (or use a disk light)".into();
            }
            e
        })
    }

    /// A shape's `emission`, where given: it makes the shape a light.
    fn emission(&self, i: usize, e: &Option<Spanned<V3>>) -> Result<Option<Color>, SceneError> {
        e.as_ref().map(|e| self.color(&at(e, format!("shapes[{i}].emission")))).transpose()
    }

    /// `n` corners.
    fn vertices(&self, v: &Spanned<Vec<V3>>, field: String, n: usize) -> Result<Vec<Vec3>, SceneError> {
        if v.get_ref().len() != n {
            return self.fail(v.span(), &field, format!("needs {n} vertices, got {}", v.get_ref().len()));
        }
        v.get_ref().iter().map(|p| self.finite(&At { value: p, span: v.span(), field: field.clone() })).collect()
    }

    /// Triangles of a triangle or mesh shape: lights when emissive, else
    /// primitives of the named material. Zero-area triangles are dropped.
    /// Triangles of shape `i` (with their vertex normals, if smooth, and
    /// texture coordinates, if it has them).
    pub(super) fn triangles(
        &mut self,
        i: usize,
        material: &Option<Spanned<String>>,
        emission: Option<Color>,
        triangles: &[Triangle],
        (normals, uvs): Corners,
        span: Range<usize>,
    ) -> Result<Vec<usize>, SceneError> {
        let mut kept = Vec::with_capacity(triangles.len());
        let mut kept_at = Vec::with_capacity(triangles.len());
        let mut kept_uvs = Vec::new();
        for (j, t) in triangles.iter().enumerate() {
            if !(t.area() > 0.0 && t.normal.is_finite()) {
                continue;
            }
            let mut t = *t;
            if let Some(n) = normals.map(|n| n[j]).filter(|n| n.iter().all(|v| *v != Vec3::ZERO)) {
                t.shading = self.shading_normals.len() as u32;
                self.shading_normals.push(n);
            }
            kept.push(t);
            kept_at.push(j);
            if let Some(uvs) = uvs {
                kept_uvs.push(uvs[j]);
            }
        }
        if kept.is_empty() {
            return self.fail(span, &format!("shapes[{i}]"), "has no triangle of non-zero area");
        }
        let field = format!("shapes[{i}].material");
        match emission {
            Some(radiance) => {
                let material = match material {
                    Some(m) => Some(self.material_ref(m, field)?),
                    None => None,
                };
                let place = self.origins.objects[i].clone();
                for t in kept {
                    self.lights.push(AreaLight::unplaced(Emitting::Triangle(t), radiance, material));
                    self.origins.lights.push(place.clone());
                }
            }
            None => {
                let Some(m) = material else {
                    // Said at the shape's `type`, as any missing field.
                    let mut place = self.origins.objects[i].clone();
                    place.field += ".material";
                    return Err(self.origins.error(&place, "missing field `material` (required without `emission`)"));
                };
                let material = self.material_ref(m, field)?;
                let object = i as u32;
                for (k, uv) in kept_uvs.into_iter().enumerate() {
                    self.surface_uv(self.prims.len() + k, SurfaceUv::Triangle(uv));
                }
                self.prims.extend(kept.into_iter().map(|t| Prim { shape: Shape::Triangle(t), material, object }));
            }
        }
        Ok(kept_at)
    }
}

/// A PLY file's triangles (with their vertex normals, turned to the side
/// of the winding, and texture coordinates where it has them), and its
/// attributes per triangle's corners (a face's value at all three), named
/// as Mitsuba names them (`vertex_color`, `face_color`, …).
type Attributes = Vec<(String, Vec<[Color; 3]>)>;
fn ply_mesh(path: &std::path::Path) -> Result<(crate::scene::mesh::ObjMesh, Attributes), String> {
    let m = crate::scene::ply::load_ply(path)?;
    let triangles: Vec<[Vec3; 3]> = m.triangles.iter().map(|t| t.map(|i| m.positions[i as usize])).collect();
    let normals = m.normals.as_ref().map(|n| {
        m.triangles
            .iter()
            .zip(&triangles)
            .map(|(t, v)| {
                let c = t.map(|i| n[i as usize].normalize_or_zero());
                let face = (v[1] - v[0]).cross(v[2] - v[0]);
                if (c[0] + c[1] + c[2]).dot(face) < 0.0 {
                    c.map(|x| -x)
                } else {
                    c
                }
            })
            .collect()
    });
    let uvs = m.uvs.as_ref().map(|uv| m.triangles.iter().map(|t| t.map(|i| uv[i as usize])).collect());
    let attributes = m
        .attributes
        .iter()
        .map(|a| {
            let at = |f: usize, t: &[u32; 3]| if a.per_face { [a.color(f); 3] } else { t.map(|i| a.color(i as usize)) };
            (a.name.clone(), m.triangles.iter().enumerate().map(|(f, t)| at(f, t)).collect())
        })
        .collect();
    Ok((crate::scene::mesh::ObjMesh { triangles, normals, uvs }, attributes))
}
