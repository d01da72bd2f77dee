//! `[[shapes]]`: geometry, each of a named material or emissive.

use super::build::{at, At, Builder};
use super::defs::V3;
use super::SceneError;
use crate::light::Emitting;
use crate::math::Color;
use crate::scene::mesh::load_obj;
use crate::scene::{tncg15_room, LightSpec, Prim};
use crate::shape::{tetrahedron, Disk, Ellipsoid, Shape, Sphere, Triangle};
use glam::{Affine3A, Vec3};
use serde::Deserialize;
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeDef {
    #[serde(rename = "type")]
    pub kind: Spanned<String>,
    pub material: Option<Spanned<String>>,
    pub emission: Option<Spanned<V3>>,
    pub vertices: Option<Spanned<Vec<V3>>>,
    pub center: Option<Spanned<V3>>,
    pub radius: Option<Spanned<f32>>,
    pub normal: Option<Spanned<V3>>,
    pub file: Option<Spanned<String>>,
    pub face_normals: Option<Spanned<bool>>,
    pub transform: Option<Vec<Spanned<StepDef>>>,
    pub floor: Option<Spanned<String>>,
    pub ceiling: Option<Spanned<String>>,
    pub walls: Option<Spanned<Vec<Spanned<String>>>>,
}

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
    pub(super) fn transform(&self, i: usize, steps: &Option<Vec<Spanned<StepDef>>>) -> Result<Affine3A, SceneError> {
        let mut m = Affine3A::IDENTITY;
        for (j, step) in steps.iter().flatten().enumerate() {
            let field = format!("shapes[{i}].transform[{j}]");
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

    pub(super) fn shape(&mut self, i: usize, s: &Spanned<ShapeDef>) -> Result<(), SceneError> {
        let d = s.get_ref();
        let kind = at(&d.kind, format!("shapes[{i}].type"));
        let present = [
            ("material", d.material.as_ref().map(|x| x.span())),
            ("emission", d.emission.as_ref().map(|x| x.span())),
            ("vertices", d.vertices.as_ref().map(|x| x.span())),
            ("center", d.center.as_ref().map(|x| x.span())),
            ("radius", d.radius.as_ref().map(|x| x.span())),
            ("normal", d.normal.as_ref().map(|x| x.span())),
            ("file", d.file.as_ref().map(|x| x.span())),
            ("face_normals", d.face_normals.as_ref().map(|x| x.span())),
            ("transform", d.transform.as_ref().and_then(|x| x.first()).map(|x| x.span())),
            ("floor", d.floor.as_ref().map(|x| x.span())),
            ("ceiling", d.ceiling.as_ref().map(|x| x.span())),
            ("walls", d.walls.as_ref().map(|x| x.span())),
        ];
        let only = |keep: &[&str]| -> Vec<(&str, Option<Range<usize>>)> {
            present.iter().filter(|(n, _)| !keep.contains(n)).cloned().collect()
        };
        let f = |n: &str| format!("shapes[{i}].{n}");
        // A triangle or mesh with `emission` is a light; with a material too
        // it also reflects (a glowing surface).
        let emission = match &d.emission {
            Some(e) => Some(self.color(&at(e, f("emission")))?),
            None => None,
        };
        let vertices = |n: usize| -> Result<Vec<Vec3>, SceneError> {
            let v = self.need(&d.vertices, &kind, "vertices")?;
            if v.value.len() != n {
                return self.fail(v.span, &v.field, format!("needs {n} vertices, got {}", v.value.len()));
            }
            v.value
                .iter()
                .map(|p| self.finite(&At { value: p, span: v.span.clone(), field: v.field.clone() }))
                .collect()
        };
        match kind.value.as_str() {
            "triangle" => {
                self.reject(&kind, &only(&["material", "emission", "vertices"]))?;
                let v = vertices(3)?;
                let t = Triangle::new(v[0], v[1], v[2]);
                self.triangles(i, &kind, &d.material, emission, &[t], None, &d.vertices)?;
            }
            "quad" => {
                self.reject(&kind, &only(&["material", "emission", "vertices"]))?;
                let v = vertices(4)?;
                // Planar: the fourth corner on the plane of the first three.
                let n = (v[1] - v[0]).cross(v[2] - v[0]);
                let size = (v[2] - v[0]).length().max((v[3] - v[1]).length());
                if !((v[3] - v[0]).dot(n.normalize_or_zero()).abs() <= 1e-4 * size) {
                    let span = d.vertices.as_ref().map_or(kind.span.clone(), |v| v.span());
                    return self.fail(span, &f("vertices"), "the four corners of a quad must lie in one plane");
                }
                let quad = [Triangle::new(v[0], v[1], v[2]), Triangle::new(v[0], v[2], v[3])];
                self.triangles(i, &kind, &d.material, emission, &quad, None, &d.vertices)?;
            }
            "mesh" => {
                self.reject(&kind, &only(&["material", "emission", "file", "face_normals", "transform"]))?;
                let file = self.need(&d.file, &kind, "file")?;
                let m = self.transform(i, &d.transform)?;
                let obj_path = self.src.path.parent().unwrap_or(Path::new(".")).join(file.value);
                let mesh = load_obj(&obj_path).map_err(|e| self.src.error(file.span.clone(), file.field.clone(), e))?;
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
                self.triangles(i, &kind, &d.material, emission, &triangles, normals.as_deref(), &d.vertices)?;
            }
            "sphere" | "ellipsoid" | "tetrahedron" | "disk" | "room" if emission.is_some() => {
                let e = d.emission.as_ref().map(|e| e.span()).unwrap_or(kind.span.clone());
                return self.fail(
                    e,
                    &f("emission"),
                    "only triangles and meshes can be made emissive (or use a disk light)",
                );
            }
            "sphere" => {
                self.reject(&kind, &only(&["material", "center", "radius"]))?;
                let material = self.material_ref(&kind, &d.material)?;
                let center = self.finite(&self.need(&d.center, &kind, "center")?)?;
                let radius = self.number(&self.need(&d.radius, &kind, "radius")?, 0.0, f32::INFINITY, true)?;
                self.prims.push(Prim { shape: Shape::Sphere(Sphere { center, radius }), material, object: i as u32 });
            }
            "ellipsoid" => {
                self.reject(&kind, &only(&["material", "transform"]))?;
                let material = self.material_ref(&kind, &d.material)?;
                let m = self.transform(i, &d.transform)?;
                let e = Ellipsoid::new(m)
                    .ok_or_else(|| self.src.error(kind.span.clone(), f("transform"), "the transform is singular"))?;
                self.prims.push(Prim { shape: Shape::Ellipsoid(e), material, object: i as u32 });
            }
            "tetrahedron" => {
                self.reject(&kind, &only(&["material", "vertices"]))?;
                let material = self.material_ref(&kind, &d.material)?;
                let v = vertices(4)?;
                for t in tetrahedron(v[0], v[1], v[2], v[3]) {
                    self.prims.push(Prim { shape: Shape::Triangle(t), material, object: i as u32 });
                }
            }
            "disk" => {
                self.reject(&kind, &only(&["material", "center", "normal", "radius"]))?;
                let material = self.material_ref(&kind, &d.material)?;
                let center = self.finite(&self.need(&d.center, &kind, "center")?)?;
                let normal = self.direction(&self.need(&d.normal, &kind, "normal")?)?;
                let radius = self.number(&self.need(&d.radius, &kind, "radius")?, 0.0, f32::INFINITY, true)?;
                self.prims.push(Prim {
                    shape: Shape::Disk(Disk { center, normal, radius }),
                    material,
                    object: i as u32,
                });
            }
            "room" => {
                self.reject(&kind, &only(&["floor", "ceiling", "walls"]))?;
                let floor = self.material_ref(&kind, &d.floor)?;
                let ceiling = self.material_ref(&kind, &d.ceiling)?;
                let walls_def = self.need(&d.walls, &kind, "walls")?;
                if walls_def.value.len() != 6 {
                    return self.fail(
                        walls_def.span,
                        &walls_def.field,
                        format!("needs 6 wall materials, got {}", walls_def.value.len()),
                    );
                }
                let mut walls = [0u32; 6];
                for (w, name) in walls.iter_mut().zip(walls_def.value.iter()) {
                    *w = self.material_ref(&kind, &Some(name.clone()))?;
                }
                self.prims.extend(tncg15_room(floor, ceiling, walls, i as u32));
            }
            other => {
                return self.fail(
                    kind.span.clone(),
                    &kind.field,
                    format!(
                    "unknown shape type \"{other}\" (triangle, quad, mesh, sphere, ellipsoid, tetrahedron, disk, room)"
                ),
                )
            }
        }
        Ok(())
    }

    /// Triangles of a triangle or mesh shape: lights when emissive, else
    /// primitives of the named material. Zero-area triangles are dropped.
    /// Triangles of shape `i` (with their vertex normals, if smooth).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn triangles(
        &mut self,
        i: usize,
        kind: &At<String>,
        material: &Option<Spanned<String>>,
        emission: Option<Color>,
        triangles: &[Triangle],
        normals: Option<&[[Vec3; 3]]>,
        vertices: &Option<Spanned<Vec<V3>>>,
    ) -> Result<(), SceneError> {
        let mut kept = Vec::with_capacity(triangles.len());
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
        }
        if kept.is_empty() {
            let span = vertices.as_ref().map_or(kind.span.clone(), |v| v.span());
            return self.fail(span, &kind.field.replace(".type", ""), "has no triangle of non-zero area");
        }
        match emission {
            Some(radiance) => {
                let material = match material {
                    Some(_) => Some(self.material_ref(kind, material)?),
                    None => None,
                };
                let place = self.origins.objects[i].clone();
                for t in kept {
                    self.lights.push(LightSpec::Area { surface: Emitting::Triangle(t), radiance, material });
                    self.origins.lights.push(place.clone());
                }
            }
            None => {
                let material = self.material_ref(kind, material)?;
                let object = i as u32;
                self.prims.extend(kept.into_iter().map(|t| Prim { shape: Shape::Triangle(t), material, object }));
            }
        }
        Ok(())
    }
}
