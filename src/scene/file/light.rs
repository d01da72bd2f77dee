//! `[[lights]]`: disk, point and directional lights.

use super::build::{at, Builder};
use super::defs::V3;
use super::SceneError;
use crate::light::Emitting;
use crate::scene::LightSpec;
use crate::shape::Disk;
use serde::Deserialize;
use std::ops::Range;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightDef {
    #[serde(rename = "type")]
    pub kind: Spanned<String>,
    pub center: Option<Spanned<V3>>,
    pub normal: Option<Spanned<V3>>,
    pub radius: Option<Spanned<f32>>,
    pub radiance: Option<Spanned<V3>>,
    pub position: Option<Spanned<V3>>,
    pub direction: Option<Spanned<V3>>,
    pub color: Option<Spanned<V3>>,
    pub falloff: Option<Spanned<f32>>,
    pub dead_distance: Option<Spanned<f32>>,
}

impl Builder<'_> {
    pub(super) fn light(&mut self, i: usize, l: &Spanned<LightDef>) -> Result<(), SceneError> {
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
}
