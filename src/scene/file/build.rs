//! A scene file's structure checked and turned into [`SceneParts`]: every
//! value in range, every name defined, every field one its type uses.

use super::defs::*;
use super::locate::Source;
use super::{SceneError, SceneFile};
use crate::camera::Camera;
use crate::light::Emitting;
use crate::material::{Material, Phong};
use crate::math::Color;
use crate::scene::mesh::load_obj;
use crate::scene::{tncg15_room, LightSpec, Prim, SceneParts};
use crate::shape::{tetrahedron, Disk, Ellipsoid, Shape, Sphere, Triangle};
use glam::{Affine3A, Vec3};
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

/// Builds the scene from its checked structure.
pub fn build(src: Source, def: FileDef) -> Result<SceneFile, SceneError> {
    Builder {
        src,
        materials: Vec::new(),
        names: BTreeMap::new(),
        prims: Vec::new(),
        lights: Vec::new(),
        not_physical: Vec::new(),
    }
    .build(def)
}

struct Builder<'a> {
    src: Source<'a>,
    materials: Vec<Material>,
    names: BTreeMap<String, u32>,
    prims: Vec<Prim>,
    lights: Vec<LightSpec>,
    not_physical: Vec<SceneError>,
}

/// A value with its span and its place in the file, for checks.
struct At<'v, T> {
    value: &'v T,
    span: Range<usize>,
    field: String,
}

fn at<'v, T>(s: &'v Spanned<T>, field: String) -> At<'v, T> {
    At { value: s.get_ref(), span: s.span(), field }
}

impl Builder<'_> {
    fn fail<T>(&self, span: Range<usize>, field: &str, message: impl Into<String>) -> Result<T, SceneError> {
        Err(self.src.error(span, field, message))
    }

    fn finite(&self, v: &At<V3>) -> Result<Vec3, SceneError> {
        let x = Vec3::from_array(*v.value);
        if !x.is_finite() {
            return self.fail(v.span.clone(), &v.field, format!("must be finite, got {x}"));
        }
        Ok(x)
    }

    fn color(&self, v: &At<V3>) -> Result<Color, SceneError> {
        let c = self.finite(v)?;
        if c.min_element() < 0.0 {
            return self.fail(v.span.clone(), &v.field, format!("must not be negative, got {c}"));
        }
        Ok(c)
    }

    fn direction(&self, v: &At<V3>) -> Result<Vec3, SceneError> {
        let d = self.finite(v)?;
        d.try_normalize().ok_or_else(|| self.src.error(v.span.clone(), &v.field, "must not be the zero vector"))
    }

    fn number(&self, v: &At<f32>, lo: f32, hi: f32, open_lo: bool) -> Result<f32, SceneError> {
        let x = *v.value;
        let ok = x.is_finite() && x <= hi && if open_lo { x > lo } else { x >= lo };
        if !ok {
            let range = match (open_lo, hi.is_finite()) {
                (true, false) => format!("must be > {lo}"),
                (false, false) => format!("must be >= {lo}"),
                (true, true) => format!("must be in ({lo}, {hi}]"),
                (false, true) => format!("must be in [{lo}, {hi}]"),
            };
            return self.fail(v.span.clone(), &v.field, format!("{range}, got {x}"));
        }
        Ok(x)
    }

    /// A required field: missing fields are reported at the table's `type`.
    fn need<'v, T>(&self, v: &'v Option<Spanned<T>>, owner: &At<String>, name: &str) -> Result<At<'v, T>, SceneError> {
        let prefix = owner.field.trim_end_matches(".type");
        match v {
            Some(s) => Ok(at(s, format!("{prefix}.{name}"))),
            None => self.fail(
                owner.span.clone(),
                &format!("{prefix}.{name}"),
                format!("missing field `{name}` (required for type \"{}\")", owner.value),
            ),
        }
    }

    /// Fields that a type does not use are mistakes, not silently ignored.
    fn reject(&self, owner: &At<String>, present: &[(&str, Option<Range<usize>>)]) -> Result<(), SceneError> {
        let prefix = owner.field.trim_end_matches(".type");
        if let Some((name, Some(span))) = present.iter().find(|(_, s)| s.is_some()) {
            return self.fail(
                span.clone(),
                &format!("{prefix}.{name}"),
                format!("field `{name}` does not apply to type \"{}\"", owner.value),
            );
        }
        Ok(())
    }

    fn build(mut self, def: FileDef) -> Result<SceneFile, SceneError> {
        for (name, m) in &def.materials {
            let material = self.material(name, m)?;
            if let Material::Phong(p) = material {
                if p.albedo_bound() > 1.0 {
                    self.not_physical.push(self.src.error(
                        m.get_ref().kind.span(),
                        format!("materials.{name}"),
                        format!(
                            "m_l C + m_s S + m_r C reaches {:.3} > 1: the material reflects more light than it \
                             receives, which photon mapping cannot render (lower m_l, m_s or m_r)",
                            p.albedo_bound()
                        ),
                    ));
                }
            }
            self.materials.push(material);
            self.names.insert(name.clone(), self.materials.len() as u32 - 1);
        }
        for (i, s) in def.shapes.iter().enumerate() {
            self.shape(i, s)?;
        }
        for (i, l) in def.lights.iter().enumerate() {
            self.light(i, l)?;
        }
        let (camera, rays_per_pixel_edge) = self.camera(&def.camera)?;
        let ambient = match &def.ambient {
            Some(a) => self.color(&at(a, "ambient".into()))?,
            None => Color::ZERO,
        };
        if ambient != Color::ZERO {
            let span = def.ambient.as_ref().map_or(0..0, |a| a.span());
            self.not_physical.push(self.src.error(
                span,
                "ambient",
                "ambient light is the Whitted approximation of indirect light; photon mapping computes indirect \
                 light itself (remove `ambient` or set it to [0, 0, 0])",
            ));
        }
        let parts = SceneParts { prims: self.prims, materials: self.materials, lights: self.lights, ambient, camera };
        Ok(SceneFile { parts, rays_per_pixel_edge, not_physical: self.not_physical })
    }

    fn material(&self, name: &str, m: &Spanned<MaterialDef>) -> Result<Material, SceneError> {
        let d = m.get_ref();
        let f = |n: &str| format!("materials.{name}.{n}");
        let kind = at(&d.kind, f("type"));
        let span = |o: &Option<Spanned<V3>>| o.as_ref().map(|s| s.span());
        let span1 = |o: &Option<Spanned<f32>>| o.as_ref().map(|s| s.span());
        let phong_fields = [
            ("color", span(&d.color)),
            ("m_a", span1(&d.m_a)),
            ("m_l", span1(&d.m_l)),
            ("m_s", span1(&d.m_s)),
            ("m_sm", span1(&d.m_sm)),
            ("m_sp", span1(&d.m_sp)),
            ("m_r", span1(&d.m_r)),
        ];
        let others = |keep: &[&str]| -> Vec<(&str, Option<Range<usize>>)> {
            let mut all = vec![
                ("rho", span(&d.rho)),
                ("reflectance", span(&d.reflectance)),
                ("ior", span1(&d.ior)),
                ("absorption", span(&d.absorption)),
            ];
            all.extend(phong_fields.iter().cloned());
            all.into_iter().filter(|(n, _)| !keep.contains(n)).collect()
        };
        match kind.value.as_str() {
            "lambertian" => {
                self.reject(&kind, &others(&["rho"]))?;
                let rho = self.color(&self.need(&d.rho, &kind, "rho")?)?;
                self.albedo(rho, &self.need(&d.rho, &kind, "rho")?)?;
                Ok(Material::Lambertian { rho })
            }
            "mirror" => {
                self.reject(&kind, &others(&["reflectance"]))?;
                let r = self.need(&d.reflectance, &kind, "reflectance")?;
                let reflectance = self.color(&r)?;
                self.albedo(reflectance, &r)?;
                Ok(Material::Mirror { reflectance })
            }
            "glass" => {
                self.reject(&kind, &others(&["ior", "absorption"]))?;
                let ior = self.number(&self.need(&d.ior, &kind, "ior")?, 0.0, 10.0, true)?;
                let absorption = match &d.absorption {
                    Some(a) => self.color(&at(a, f("absorption")))?,
                    None => Color::ZERO,
                };
                Ok(Material::Glass { ior, absorption })
            }
            "phong" => {
                self.reject(&kind, &others(&["color", "m_a", "m_l", "m_s", "m_sm", "m_sp", "m_r"]))?;
                let color = self.color(&self.need(&d.color, &kind, "color")?)?;
                let coef = |v: &Option<Spanned<f32>>, n: &str, hi: f32| -> Result<f32, SceneError> {
                    match v {
                        Some(s) => self.number(&at(s, f(n)), 0.0, hi, false),
                        None => Ok(0.0),
                    }
                };
                Ok(Material::Phong(Phong {
                    color,
                    ambient: coef(&d.m_a, "m_a", f32::INFINITY)?,
                    diffuse: coef(&d.m_l, "m_l", f32::INFINITY)?,
                    specular: coef(&d.m_s, "m_s", f32::INFINITY)?,
                    metalness: coef(&d.m_sm, "m_sm", 1.0)?,
                    shininess: coef(&d.m_sp, "m_sp", 1e6)?,
                    mirror: coef(&d.m_r, "m_r", f32::INFINITY)?,
                }))
            }
            other => self.fail(
                kind.span.clone(),
                &kind.field,
                format!("unknown material type \"{other}\" (lambertian, mirror, glass, phong)"),
            ),
        }
    }

    /// A reflectance over one creates energy.
    fn albedo(&self, c: Color, v: &At<V3>) -> Result<(), SceneError> {
        if c.max_element() > 1.0 {
            return self.fail(v.span.clone(), &v.field, format!("a reflectance must be at most 1, got {c}"));
        }
        Ok(())
    }

    fn material_ref(&self, kind: &At<String>, m: &Option<Spanned<String>>) -> Result<u32, SceneError> {
        let name = self.need(m, kind, "material")?;
        self.names.get(name.value.as_str()).copied().ok_or_else(|| {
            let known: Vec<&str> = self.names.keys().map(String::as_str).collect();
            self.src.error(
                name.span.clone(),
                name.field.clone(),
                format!("no material named \"{}\" (defined: {})", name.value, known.join(", ")),
            )
        })
    }

    fn transform(&self, i: usize, steps: &Option<Vec<Spanned<StepDef>>>) -> Result<Affine3A, SceneError> {
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

    fn shape(&mut self, i: usize, s: &Spanned<ShapeDef>) -> Result<(), SceneError> {
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
                self.triangles(&kind, &d.material, emission, &[t], &d.vertices)?;
            }
            "mesh" => {
                self.reject(&kind, &only(&["material", "emission", "file", "transform"]))?;
                let file = self.need(&d.file, &kind, "file")?;
                let m = self.transform(i, &d.transform)?;
                let obj_path = self.src.path.parent().unwrap_or(Path::new(".")).join(file.value);
                let triangles = load_obj(&obj_path)
                    .map_err(|e| self.src.error(file.span.clone(), file.field.clone(), e))?
                    .into_iter()
                    .map(|[a, b, c]| Triangle::new(m.transform_point3(a), m.transform_point3(b), m.transform_point3(c)))
                    .collect::<Vec<_>>();
                self.triangles(&kind, &d.material, emission, &triangles, &d.vertices)?;
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
                self.prims.push(Prim { shape: Shape::Sphere(Sphere { center, radius }), material });
            }
            "ellipsoid" => {
                self.reject(&kind, &only(&["material", "transform"]))?;
                let material = self.material_ref(&kind, &d.material)?;
                let m = self.transform(i, &d.transform)?;
                let e = Ellipsoid::new(m)
                    .ok_or_else(|| self.src.error(kind.span.clone(), f("transform"), "the transform is singular"))?;
                self.prims.push(Prim { shape: Shape::Ellipsoid(e), material });
            }
            "tetrahedron" => {
                self.reject(&kind, &only(&["material", "vertices"]))?;
                let material = self.material_ref(&kind, &d.material)?;
                let v = vertices(4)?;
                for t in tetrahedron(v[0], v[1], v[2], v[3]) {
                    self.prims.push(Prim { shape: Shape::Triangle(t), material });
                }
            }
            "disk" => {
                self.reject(&kind, &only(&["material", "center", "normal", "radius"]))?;
                let material = self.material_ref(&kind, &d.material)?;
                let center = self.finite(&self.need(&d.center, &kind, "center")?)?;
                let normal = self.direction(&self.need(&d.normal, &kind, "normal")?)?;
                let radius = self.number(&self.need(&d.radius, &kind, "radius")?, 0.0, f32::INFINITY, true)?;
                self.prims.push(Prim { shape: Shape::Disk(Disk { center, normal, radius }), material });
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
                self.prims.extend(tncg15_room(floor, ceiling, walls));
            }
            other => {
                return self.fail(
                    kind.span.clone(),
                    &kind.field,
                    format!(
                        "unknown shape type \"{other}\" (triangle, mesh, sphere, ellipsoid, tetrahedron, disk, room)"
                    ),
                )
            }
        }
        Ok(())
    }

    /// Triangles of a triangle or mesh shape: lights when emissive, else
    /// primitives of the named material. Zero-area triangles are dropped.
    fn triangles(
        &mut self,
        kind: &At<String>,
        material: &Option<Spanned<String>>,
        emission: Option<Color>,
        triangles: &[Triangle],
        vertices: &Option<Spanned<Vec<V3>>>,
    ) -> Result<(), SceneError> {
        let kept: Vec<Triangle> =
            triangles.iter().copied().filter(|t| t.area() > 0.0 && t.normal.is_finite()).collect();
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
                for t in kept {
                    self.lights.push(LightSpec::Area { surface: Emitting::Triangle(t), radiance, material });
                }
            }
            None => {
                let material = self.material_ref(kind, material)?;
                self.prims.extend(kept.into_iter().map(|t| Prim { shape: Shape::Triangle(t), material }));
            }
        }
        Ok(())
    }

    fn light(&mut self, i: usize, l: &Spanned<LightDef>) -> Result<(), SceneError> {
        let d = l.get_ref();
        let kind = at(&d.kind, format!("lights[{i}].type"));
        let s3 = |o: &Option<Spanned<V3>>| o.as_ref().map(|x| x.span());
        let s1 = |o: &Option<Spanned<f32>>| o.as_ref().map(|x| x.span());
        let present = [
            ("center", s3(&d.center)),
            ("normal", s3(&d.normal)),
            ("radius", s1(&d.radius)),
            ("radiance", s3(&d.radiance)),
            ("position", s3(&d.position)),
            ("direction", s3(&d.direction)),
            ("color", s3(&d.color)),
            ("falloff", s1(&d.falloff)),
            ("dead_distance", s1(&d.dead_distance)),
        ];
        let only = |keep: &[&str]| -> Vec<(&str, Option<Range<usize>>)> {
            present.iter().filter(|(n, _)| !keep.contains(n)).cloned().collect()
        };
        let spec = match kind.value.as_str() {
            "disk" => {
                self.reject(&kind, &only(&["center", "normal", "radius", "radiance"]))?;
                let center = self.finite(&self.need(&d.center, &kind, "center")?)?;
                let normal = self.direction(&self.need(&d.normal, &kind, "normal")?)?;
                let radius = self.number(&self.need(&d.radius, &kind, "radius")?, 0.0, f32::INFINITY, true)?;
                let radiance = self.color(&self.need(&d.radiance, &kind, "radiance")?)?;
                LightSpec::Area { surface: Emitting::Disk(Disk { center, normal, radius }), radiance, material: None }
            }
            "point" => {
                self.reject(&kind, &only(&["position", "color", "falloff", "dead_distance"]))?;
                let position = self.finite(&self.need(&d.position, &kind, "position")?)?;
                let intensity = self.color(&self.need(&d.color, &kind, "color")?)?;
                let falloff = match &d.falloff {
                    Some(v) => self.number(&at(v, format!("lights[{i}].falloff")), 0.0, 16.0, false)?,
                    None => 2.0,
                };
                let dead_distance = match &d.dead_distance {
                    Some(v) => self.number(&at(v, format!("lights[{i}].dead_distance")), 0.0, f32::INFINITY, false)?,
                    None => 0.0,
                };
                if falloff != 2.0 || dead_distance != 0.0 {
                    let span = d.falloff.as_ref().or(d.dead_distance.as_ref()).map_or(kind.span.clone(), |v| v.span());
                    self.not_physical.push(self.src.error(
                        span,
                        format!("lights[{i}]"),
                        format!(
                            "falloff {falloff} and dead_distance {dead_distance}: light from a point dims as 1/d^2, \
                             so photon mapping needs falloff = 2 and dead_distance = 0"
                        ),
                    ));
                }
                LightSpec::Point { position, intensity, falloff, dead_distance }
            }
            "directional" => {
                self.reject(&kind, &only(&["direction", "color"]))?;
                let direction = self.direction(&self.need(&d.direction, &kind, "direction")?)?;
                let irradiance = self.color(&self.need(&d.color, &kind, "color")?)?;
                LightSpec::Directional { direction, irradiance }
            }
            other => {
                return self.fail(
                    kind.span.clone(),
                    &kind.field,
                    format!("unknown light type \"{other}\" (disk, point, directional)"),
                )
            }
        };
        self.lights.push(spec);
        Ok(())
    }

    fn camera(&self, c: &Spanned<CameraDef>) -> Result<(Camera, u32), SceneError> {
        let d = c.get_ref();
        let f = |n: &str| format!("camera.{n}");
        let eye = self.finite(&at(&d.eye, f("eye")))?;
        let size = |v: &Spanned<i64>, n: &str| -> Result<u32, SceneError> {
            let x = *v.get_ref();
            if !(1..=65536).contains(&x) {
                return self.fail(v.span(), &f(n), format!("must be in [1, 65536], got {x}"));
            }
            Ok(x as u32)
        };
        let (width, height) = (size(&d.width, "width")?, size(&d.height, "height")?);
        let n = match &d.rays_per_pixel_edge {
            Some(v) => {
                let x = *v.get_ref();
                if !(1..=64).contains(&x) {
                    return self.fail(v.span(), &f("rays_per_pixel_edge"), format!("must be in [1, 64], got {x}"));
                }
                x as u32
            }
            None => 1,
        };
        let corners = [&d.lower_left, &d.lower_right, &d.upper_left, &d.upper_right];
        let look = [d.target.as_ref().map(|s| s.span()), d.up.as_ref().map(|s| s.span())];
        let camera = if corners.iter().any(|c| c.is_some()) {
            if let Some(span) = look.iter().flatten().next().cloned().or(d.vfov.as_ref().map(|s| s.span())) {
                return self.fail(span, "camera", "give either the four corners or target/up/vfov, not both");
            }
            let names = ["lower_left", "lower_right", "upper_left", "upper_right"];
            let mut p = [Vec3::ZERO; 4];
            for ((slot, c), name) in p.iter_mut().zip(corners).zip(names) {
                let Some(c) = c else {
                    return self.fail(
                        c_span(c, &d.eye),
                        &f(name),
                        format!("missing field `{name}` (all four corners are needed)"),
                    );
                };
                *slot = self.finite(&at(c, f(name)))?;
            }
            let [ll, lr, ul, ur] = p;
            // The corners must form a parallelogram the eye is not on.
            let err = ((lr - ll) - (ur - ul)).length();
            let size = (lr - ll).length().max((ul - ll).length());
            if !(size > 0.0) || err > 1e-4 * size || (ul - ll).cross(lr - ll).dot(ll - eye).abs() <= 1e-12 * size * size
            {
                return self.fail(
                    c.span(),
                    "camera",
                    "the corners must form a rectangle in a plane not through the eye",
                );
            }
            Camera::from_corners(eye, [lr, ll, ul, ur], width, height)
        } else {
            let target = self.finite(&self.need_cam(&d.target, c, "target")?)?;
            let up = self.direction(&self.need_cam(&d.up, c, "up")?)?;
            let vfov = self.number(&self.need_cam(&d.vfov, c, "vfov")?, 0.0, 179.0, true)?;
            let forward = (target - eye).try_normalize().ok_or_else(|| {
                self.src.error(
                    d.target.as_ref().map_or(c.span(), |t| t.span()),
                    f("target"),
                    "must differ from the eye",
                )
            })?;
            let right = forward.cross(up).try_normalize().ok_or_else(|| {
                self.src.error(
                    d.up.as_ref().map_or(c.span(), |t| t.span()),
                    f("up"),
                    "must not be parallel to the view direction",
                )
            })?;
            let true_up = right.cross(forward);
            let h = (vfov.to_radians() * 0.5).tan();
            let w = h * width as f32 / height as f32;
            let centre = eye + forward;
            let ll = centre - right * w - true_up * h;
            let lr = centre + right * w - true_up * h;
            let ul = centre - right * w + true_up * h;
            let ur = centre + right * w + true_up * h;
            Camera::from_corners(eye, [lr, ll, ul, ur], width, height)
        };
        Ok((camera, n))
    }

    fn need_cam<'v, T>(
        &self,
        v: &'v Option<Spanned<T>>,
        c: &Spanned<CameraDef>,
        name: &str,
    ) -> Result<At<'v, T>, SceneError> {
        match v {
            Some(s) => Ok(at(s, format!("camera.{name}"))),
            None => self.fail(
                c.span(),
                &format!("camera.{name}"),
                format!("missing field `{name}` (give the four corners lower_left, lower_right, upper_left, upper_right, or target, up and vfov)"),
            ),
        }
    }
}

fn c_span(c: &Option<Spanned<V3>>, eye: &Spanned<V3>) -> Range<usize> {
    c.as_ref().map_or(eye.span(), |s| s.span())
}
