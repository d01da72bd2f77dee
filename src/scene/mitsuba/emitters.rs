//! Top-level `<emitter>` plugins (an `area` emitter belongs to a shape:
//! shapes.rs). Placement as Mitsuba 3 defines it (src/emitters/*.cpp): a
//! point light at `position` or `to_world`'s origin; a directional light
//! along `direction` or `to_world`'s +z; a spot light at `to_world`'s
//! origin shining along its +z.

use super::props::{Plugin, Value};
use super::spectrum::Use;
use super::Builder;
use crate::light::{Constant, Directional, Environment, Light, PointLight, Spot};
use crate::math::Color;
use crate::math::Frame;
use crate::scene::file::SceneError;
use glam::{DAffine3, DVec3};

impl Builder<'_> {
    pub(super) fn emitter(&mut self, p: &Plugin) -> Result<(), SceneError> {
        let spec = if p.kind == "envmap" { self.envmap(p) } else { self.light_of(p) };
        match spec {
            Ok(spec) => {
                self.lights.push(spec);
                self.origins.lights.push(super::place(p));
                Ok(())
            }
            Err(e) => self.substitute(p, "the emitter is left out", e),
        }
    }
}

impl Builder<'_> {
    /// An environment map from a latitude-longitude image (OpenEXR,
    /// Radiance HDR, or any image a bitmap reads).
    fn envmap(&mut self, p: &Plugin) -> Result<Light, SceneError> {
        let (name, loc) = p.string("filename")?.ok_or_else(|| p.refuse("an envmap needs a filename"))?;
        let scale = p.float_in("scale", 1.0, 0.0, 1e30)?;
        let m = p.transform("to_world")?.unwrap_or(DAffine3::IDENTITY);
        if p.boolean("mis_compensation", false)? {
            return Err(p.fail(p.loc(), "mis_compensation", "is not supported"));
        }
        p.finish("filename, scale, to_world, mis_compensation (false)")?;
        let path = self.resolve(&name, &loc)?;
        let image = crate::envmap::EnvMap::load(&path)
            .map_err(|e| p.fail(&loc, "filename", format!("{}: {e}", path.display())))?;
        if image.pixels.iter().any(|c| !c.is_finite()) {
            return Err(p.fail(&loc, "filename", "the map holds non-finite values"));
        }
        let r = m.matrix3;
        let (x, y, z) = (r.x_axis, r.y_axis, r.z_axis);
        let orthonormal = [x, y, z].iter().all(|a| (a.length() - 1.0).abs() < 1e-4)
            && x.dot(y).abs() < 1e-4
            && x.dot(z).abs() < 1e-4
            && y.dot(z).abs() < 1e-4;
        if !orthonormal {
            return Err(p.fail(p.loc(), "to_world", "an environment map's transform must be a rotation"));
        }
        let to_world = r.as_mat3();
        Ok(Light::Envmap(Environment::new(std::sync::Arc::new(crate::envmap::EnvMap::new(
            &image,
            scale as f32,
            to_world,
        )))))
    }
}

impl Builder<'_> {
    /// A texture for an emitter: its own copy (emitters hold theirs).
    pub(super) fn emitter_texture(
        &mut self,
        t: &Plugin,
    ) -> Result<std::sync::Arc<crate::texture::Texture>, SceneError> {
        let i = self.texture(t)?;
        match &self.textures[i as usize] {
            super::textures::Draft::Ready(t) => Ok(std::sync::Arc::new(t.clone())),
            super::textures::Draft::Attribute { .. } => Err(t.refuse("an emitter cannot read a mesh attribute")),
        }
    }

    fn light_of(&mut self, p: &Plugin) -> Result<Light, SceneError> {
        let spec = match p.kind {
            "point" => {
                let position = match (p.point("position")?, p.transform("to_world")?) {
                    (Some(_), Some(_)) => return Err(p.refuse("give either position or to_world, not both")),
                    (Some(x), None) => x,
                    (None, m) => m.unwrap_or(DAffine3::IDENTITY).translation,
                };
                let intensity = p.color("intensity", Use::Emission)?.unwrap_or(Color::ONE);
                p.finish("position, to_world, intensity")?;
                Light::Point(PointLight { position: position.as_vec3(), intensity, falloff: 2.0, dead_distance: 0.0 })
            }
            "directional" => {
                let direction = match (p.point("direction")?, p.transform("to_world")?) {
                    (Some(_), Some(_)) => return Err(p.refuse("give either direction or to_world, not both")),
                    (Some(d), None) => d,
                    (None, m) => m.unwrap_or(DAffine3::IDENTITY).transform_vector3(DVec3::Z),
                };
                let direction =
                    super::unit(direction).ok_or_else(|| p.fail(p.loc(), "direction", "must not be zero"))?;
                let irradiance = p.color("irradiance", Use::Emission)?.unwrap_or(Color::ONE);
                p.finish("direction, to_world, irradiance")?;
                Light::Directional(Directional::new(direction, irradiance))
            }
            "spot" => {
                let m = p.transform("to_world")?.unwrap_or(DAffine3::IDENTITY);
                let intensity = p.color("intensity", Use::Emission)?.unwrap_or(Color::ONE);
                let cutoff = p.float_in("cutoff_angle", 20.0, 1e-3, 180.0)?;
                let beam = p.float_in("beam_width", cutoff * 0.75, 0.0, 180.0)?;
                let texture = match p.value("texture", Use::Reflectance)? {
                    None => None,
                    Some(Value::Texture(t)) => Some(self.emitter_texture(&t)?),
                    Some(Value::Color(c)) => Some(std::sync::Arc::new(crate::texture::Texture::Constant(c))),
                };
                p.finish("to_world, intensity, cutoff_angle, beam_width, texture")?;
                let axis = m
                    .transform_vector3(DVec3::Z)
                    .try_normalize()
                    .ok_or_else(|| p.fail(p.loc(), "to_world", "is singular"))?;
                let pattern = match texture {
                    None => None,
                    Some(t) => {
                        let x = m.transform_vector3(DVec3::X);
                        let x = (x - axis * x.dot(axis))
                            .try_normalize()
                            .ok_or_else(|| p.fail(p.loc(), "to_world", "is singular"))?;
                        Some((t, x.as_vec3(), axis.cross(x).as_vec3()))
                    }
                };
                let (position, axis) = (m.translation.as_vec3(), axis.as_vec3());
                let (cutoff, beam) = (cutoff as f32, beam.min(cutoff) as f32);
                Light::Spot(match pattern {
                    None => Spot::new(position, Frame::from_normal(axis), intensity, cutoff, beam),
                    Some((texture, x, y)) => {
                        Spot::new(position, Frame { s: x, t: y, n: axis }, intensity, cutoff, beam)
                            .with_pattern(texture)
                    }
                })
            }
            "projector" => {
                let m = p.transform("to_world")?.unwrap_or(DAffine3::IDENTITY);
                let (irradiance, pattern) = match p.value("irradiance", Use::Emission)? {
                    None => (Color::ONE, None),
                    Some(Value::Color(c)) => (c, None),
                    Some(Value::Texture(t)) => (Color::ONE, Some(self.emitter_texture(&t)?)),
                };
                let scale = p.float_in("scale", 1.0, 0.0, 1e30)?;
                // The window has the image's aspect (a constant irradiance is
                // a 1 x 1 image: a square frustum).
                let aspect = match pattern.as_deref() {
                    Some(crate::texture::Texture::Bitmap { image, .. }) => {
                        let r = image.resolution();
                        (r.x / r.y) as f64
                    }
                    _ => 1.0,
                };
                let x_fov = super::sensor::fov(p, aspect)?;
                p.finish("to_world, irradiance, scale, fov, fov_axis")?;
                let axes = [m.matrix3.x_axis, m.matrix3.y_axis, m.matrix3.z_axis];
                let Some(axes) =
                    axes.iter().map(|a| a.try_normalize().map(|a| a.as_vec3())).collect::<Option<Vec<_>>>()
                else {
                    return Err(p.fail(p.loc(), "to_world", "is singular"));
                };
                let t = (0.5 * x_fov.to_radians()).tan();
                let pattern = pattern.map(|t| {
                    let mean = crate::light::Projector::window_mean(&t);
                    (t, mean)
                });
                Light::Projector(crate::light::Projector {
                    position: m.translation.as_vec3(),
                    axes: [axes[0], axes[1], axes[2]],
                    scaled: irradiance * (std::f32::consts::PI * scale as f32),
                    tan_x: t as f32,
                    tan_y: (t / aspect) as f32,
                    pattern,
                })
            }
            "area" => return Err(p.refuse("an area emitter must be nested in the <shape> that emits")),
            "constant" => {
                let radiance = p.color("radiance", Use::Emission)?.unwrap_or(Color::ONE);
                p.finish("radiance")?;
                Light::Constant(Constant::new(radiance))
            }
            k => {
                return Err(p.refuse(format!(
                    "the '{k}' emitter is not supported yet (point, directional, spot, constant and area are)"
                )))
            }
        };
        if let Light::Point(PointLight { intensity: c, .. })
        | Light::Spot(Spot { intensity: c, .. })
        | Light::Directional(Directional { irradiance: c, .. }) = &spec
        {
            if c.min_element() < 0.0 {
                return Err(p.refuse("emission must not be negative"));
            }
        }
        Ok(spec)
    }
}
