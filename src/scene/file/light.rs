//! `[[lights]]`: disk, point and directional lights.

use super::build::{at, Builder};
use super::defs::{Entry, V3};
use super::SceneError;
use crate::light::{AreaLight, Directional, Emitting, Light};
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
            other => {
                let kind = entry.kind();
                return self.fail(
                    kind.span.clone(),
                    &kind.field,
                    format!("unknown light type \"{other}\" (disk, point, directional)"),
                );
            }
        };
        self.lights.push(spec);
        Ok(())
    }
}
