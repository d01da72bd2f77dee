//! `[[lights]]`: disk, point and directional lights, and light from
//! everywhere: a constant sky and an environment map.

use super::build::{at, Builder};
use super::defs::{Entry, V3};
use super::shape::StepDef;
use super::SceneError;
use crate::light::{AreaLight, Constant, Directional, Emitting, Environment, Light};
use crate::shape::Disk;
use serde::Deserialize;
use toml::Spanned;

/// `type = "disk"`: a one-sided disk of uniform radiance.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DiskLight {
    center: Spanned<V3>,
    normal: Spanned<V3>,
    radius: Spanned<f32>,
    radiance: Spanned<V3>,
}

/// `type = "point"`: the course's point light, dimmed by 1 / (d + d0)^falloff.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PointLight {
    position: Spanned<V3>,
    color: Spanned<V3>,
    falloff: Option<Spanned<f32>>,
    dead_distance: Option<Spanned<f32>>,
}

/// `type = "directional"`: parallel light of irradiance `color`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DirectionalLight {
    direction: Spanned<V3>,
    color: Spanned<V3>,
}

/// `type = "sky"`: radiance arriving equally from every direction
/// (Mitsuba's `constant`).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SkyLight {
    radiance: Spanned<V3>,
}

/// `type = "envmap"`: a latitude-longitude image at infinity (Mitsuba's
/// `envmap`): its top row towards the map's +y, turned by `transform`'s
/// rotations, its values times `scale`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EnvmapLight {
    file: Spanned<String>,
    scale: Option<Spanned<f32>>,
    transform: Option<Vec<Spanned<StepDef>>>,
}

impl Builder<'_> {
    pub(super) fn light(&mut self, i: usize, mut entry: Entry) -> Result<(), SceneError> {
        let f = |n: &str| format!("lights[{i}].{n}");
        let spec = match entry.kind.get_ref().as_str() {
            "disk" => {
                let d: DiskLight = entry.read(&self.src)?;
                let center = self.finite(&at(&d.center, f("center")))?;
                let normal = self.direction(&at(&d.normal, f("normal")))?;
                let radius = self.number(&at(&d.radius, f("radius")), 0.0, f32::INFINITY, true)?;
                let radiance = self.color(&at(&d.radiance, f("radiance")))?;
                AreaLight::unplaced(Emitting::Disk(Disk { center, normal, radius }), radiance, None)
            }
            "point" => {
                let d: PointLight = entry.read(&self.src)?;
                let position = self.finite(&at(&d.position, f("position")))?;
                let intensity = self.color(&at(&d.color, f("color")))?;
                let falloff = match &d.falloff {
                    Some(v) => self.number(&at(v, f("falloff")), 0.0, 16.0, false)?,
                    None => 2.0,
                };
                let dead_distance = match &d.dead_distance {
                    Some(v) => self.number(&at(v, f("dead_distance")), 0.0, f32::INFINITY, false)?,
                    None => 0.0,
                };
                if falloff != 2.0 || dead_distance != 0.0 {
                    let span = d.falloff.as_ref().or(d.dead_distance.as_ref()).map_or(entry.kind.span(), |v| v.span());
                    self.not_physical.push(self.src.error(
                        span,
                        format!("lights[{i}]"),
                        format!(
                            "falloff {falloff} and dead_distance {dead_distance}: light from a point dims as 1/d^2, \
                             so photon mapping needs falloff = 2 and dead_distance = 0"
                        ),
                    ));
                }
                Light::Point(crate::light::PointLight { position, intensity, falloff, dead_distance })
            }
            "directional" => {
                let d: DirectionalLight = entry.read(&self.src)?;
                let direction = self.direction(&at(&d.direction, f("direction")))?;
                let irradiance = self.color(&at(&d.color, f("color")))?;
                Light::Directional(Directional::new(direction, irradiance))
            }
            "sky" => {
                let d: SkyLight = entry.read(&self.src)?;
                Light::Constant(Constant::new(self.color(&at(&d.radiance, f("radiance")))?))
            }
            "envmap" => {
                let d: EnvmapLight = entry.read(&self.src)?;
                let scale = match &d.scale {
                    Some(v) => self.number(&at(v, f("scale")), 0.0, 1e30, false)?,
                    None => 1.0,
                };
                // A map is turned, never moved or stretched: it is at infinity.
                for (j, step) in d.transform.iter().flatten().enumerate() {
                    if step.get_ref().rotate.is_none() {
                        return self.fail(
                            step.span(),
                            &f(&format!("transform[{j}]")),
                            "an environment map is only turned: each step is a rotate",
                        );
                    }
                }
                let m = self.transform(&f("transform"), &d.transform)?;
                let file = at(&d.file, f("file"));
                let path = self.src.path.parent().unwrap_or(std::path::Path::new(".")).join(file.value);
                let image = crate::envmap::EnvMap::load(&path).map_err(|e| {
                    self.src.error(file.span.clone(), file.field.clone(), format!("{}: {e}", path.display()))
                })?;
                let map = crate::envmap::EnvMap::new(&image, scale, glam::Mat3::from(m.matrix3));
                Light::Envmap(Environment::new(std::sync::Arc::new(map)))
            }
            other => {
                let kind = entry.kind();
                return self.fail(
                    kind.span.clone(),
                    &kind.field,
                    format!("unknown light type \"{other}\" (disk, point, directional, sky, envmap)"),
                );
            }
        };
        self.lights.push(spec);
        Ok(())
    }
}
