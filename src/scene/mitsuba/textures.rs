//! `<texture>` plugins (bitmap, checkerboard, mesh_attribute) as
//! [`crate::texture::Texture`]s, and the parameters that take a colour or
//! a texture. Defaults and meanings are Mitsuba 3's
//! (src/textures/*.cpp): a bitmap is filtered bilinearly and repeats, and
//! an 8-bit image is sRGB unless `raw`; a checkerboard's colours are 0.4
//! and 0.2; a texture's `to_uv` is the 2D part of its transform (the
//! upper-left 2x2 block and the x, y translation, as Mitsuba extracts it).

use super::props::{Plugin, Value};
use super::spectrum::Use;
use super::Builder;
use crate::material::Param;
use crate::math::Color;
use crate::scene::file::SceneError;
use crate::scene::Texturing;
use crate::texture::{Bitmap, Filter, SurfaceUv, Texture, Wrap};
use glam::{Affine2, DAffine3, Vec2};
use std::sync::Arc;

/// A texture as the reader holds it until the scene is complete: a mesh
/// attribute's values are filled in as the meshes that carry it are read.
pub(super) enum Draft {
    Ready(Texture),
    Attribute { name: String, scale: f32, values: Vec<[Color; 3]> },
}

impl Builder<'_> {
    /// A parameter that may be a colour or a texture; `default` where absent.
    pub(super) fn param(&mut self, p: &Plugin, name: &str, usage: Use, default: Color) -> Result<Param, SceneError> {
        match p.value(name, usage)? {
            None => Ok(Param::Fixed(default)),
            Some(Value::Color(c)) => Ok(Param::Fixed(c)),
            Some(Value::Texture(t)) => Ok(Param::Texture(self.texture(&t)?)),
        }
    }

    /// The index of a texture plugin's texture (one per element, however
    /// often it is referred to).
    pub(super) fn texture(&mut self, t: &Plugin) -> Result<u32, SceneError> {
        let key = t.el as *const _;
        if let Some(&(_, i)) = self.texture_cache.iter().find(|(k, _)| *k == key) {
            return Ok(i);
        }
        let draft = match t.kind {
            "bitmap" => {
                let (name, loc) = t.string("filename")?.ok_or_else(|| t.refuse("a bitmap needs a filename"))?;
                let raw = t.boolean("raw", false)?;
                let filter = match t.string("filter_type")? {
                    None => Filter::Bilinear,
                    Some((f, _)) if f == "bilinear" => Filter::Bilinear,
                    Some((f, _)) if f == "nearest" => Filter::Nearest,
                    Some((f, l)) => return Err(t.fail(&l, "filter_type", format!("'{f}' is not bilinear or nearest"))),
                };
                let wrap = match t.string("wrap_mode")? {
                    None => Wrap::Repeat,
                    Some((w, l)) => match w.as_str() {
                        "repeat" => Wrap::Repeat,
                        "mirror" => Wrap::Mirror,
                        "clamp" => Wrap::Clamp,
                        _ => return Err(t.fail(&l, "wrap_mode", format!("'{w}' is not repeat, mirror or clamp"))),
                    },
                };
                // Storage precision only: photonmap keeps every texel in 32 bits.
                if let Some((f, l)) = t.string("format")? {
                    if !matches!(f.as_str(), "auto" | "variant" | "uint8" | "float16" | "float32") {
                        return Err(t.fail(&l, "format", format!("'{f}' is not a bitmap storage format")));
                    }
                }
                let to_uv = to_uv(t)?;
                t.finish("filename, raw, filter_type, wrap_mode, format, to_uv")?;
                let path = self.resolve(&name, &loc)?;
                let mut image = Bitmap::load(&path, raw)
                    .map_err(|e| t.fail(&loc, "filename", format!("{}: {e}", path.display())))?;
                image.filter = filter;
                image.wrap = wrap;
                Draft::Ready(Texture::Bitmap { image: Arc::new(image), to_uv })
            }
            "checkerboard" => {
                let color = |name: &str, default: f32| match t.value(name, Use::Reflectance)? {
                    None => Ok(Color::splat(default)),
                    Some(Value::Color(c)) => Ok(c),
                    Some(Value::Texture(inner)) => {
                        Err(inner.refuse("a checkerboard's colours must be colours, not textures"))
                    }
                };
                let (color0, color1) = (color("color0", 0.4)?, color("color1", 0.2)?);
                let to_uv = to_uv(t)?;
                t.finish("color0, color1, to_uv")?;
                Draft::Ready(Texture::Checkerboard { color0, color1, to_uv })
            }
            "rawconstant" => {
                // A value used as it is: no colour conversion (rawconstant.cpp).
                let value = match t.tag_of("value") {
                    Some("vector" | "point") => t.point("value")?.unwrap_or(glam::DVec3::ONE).as_vec3(),
                    _ => match t.value("value", Use::Unbounded)? {
                        Some(Value::Color(c)) => c,
                        Some(Value::Texture(inner)) => {
                            return Err(inner.refuse("a rawconstant's value must be numbers"))
                        }
                        None => Color::ONE,
                    },
                };
                t.finish("value")?;
                Draft::Ready(Texture::Constant(value))
            }
            "mesh_attribute" => {
                let (name, loc) = t.string("name")?.ok_or_else(|| t.refuse("a mesh_attribute needs a name"))?;
                crate::material::params::attribute_name(&name).map_err(|m| t.fail(&loc, "name", m))?;
                let spec = crate::material::params::MESH_ATTRIBUTE[1];
                let scale = t.float("scale")?.map_or(spec.default, |v| v as f32);
                spec.check(Color::splat(scale)).map_err(|m| t.fail(&t.named_loc("scale"), "scale", m))?;
                t.finish("name, scale")?;
                Draft::Attribute { name, scale, values: Vec::new() }
            }
            k => {
                return Err(t.refuse(format!(
                    "the '{k}' texture is not supported (bitmap, checkerboard, mesh_attribute and rawconstant are)"
                )))
            }
        };
        let i = self.textures.len() as u32;
        self.textures.push(draft);
        self.texture_cache.push((key, i));
        Ok(i)
    }

    /// Records where the primitive just pushed reads its textures.
    pub(super) fn surface(&mut self, prim: usize, uv: SurfaceUv) {
        if self.surfaces.len() < prim {
            self.surfaces.resize(prim, SurfaceUv::Barycentric);
        }
        self.surfaces.push(uv);
    }

    /// A mesh's attributes at primitive `prim`: each attribute texture
    /// whose name the mesh carries takes the triangle's corner values.
    pub(super) fn attributes(&mut self, prim: usize, values: impl Fn(&str) -> Option<[Color; 3]>) {
        for d in &mut self.textures {
            if let Draft::Attribute { name, values: v, .. } = d {
                if let Some(c) = values(name) {
                    if v.len() <= prim {
                        v.resize(prim + 1, [Color::ZERO; 3]);
                    }
                    v[prim] = c;
                }
            }
        }
    }

    /// The scene's textures, complete.
    pub(super) fn texturing(&mut self) -> Texturing {
        let textures = std::mem::take(&mut self.textures)
            .into_iter()
            .map(|d| match d {
                Draft::Ready(t) => t,
                Draft::Attribute { scale, values, .. } => Texture::Attribute { values: Arc::new(values), scale },
            })
            .collect();
        Texturing {
            textures,
            materials: std::mem::take(&mut self.textured),
            surfaces: std::mem::take(&mut self.surfaces),
            frames: std::mem::take(&mut self.frames),
            perturb: std::mem::take(&mut self.perturb),
            light_patterns: std::mem::take(&mut self.light_patterns),
        }
    }
}

/// A texture's `to_uv`: the 2D affine part of its transform.
fn to_uv(t: &Plugin) -> Result<Affine2, SceneError> {
    let m = t.transform("to_uv")?.unwrap_or(DAffine3::IDENTITY);
    let (x, y, o) = (m.matrix3.x_axis, m.matrix3.y_axis, m.translation);
    let a = Affine2::from_cols(
        Vec2::new(x.x as f32, x.y as f32),
        Vec2::new(y.x as f32, y.y as f32),
        Vec2::new(o.x as f32, o.y as f32),
    );
    if !a.is_finite() {
        return Err(t.fail(t.loc(), "to_uv", "the transform is not finite"));
    }
    Ok(a)
}
