//! `[textures.NAME]` and the textures written inline where a material's
//! parameter takes one: `bitmap`, `checkerboard` and `mesh_attribute`
//! (a PLY mesh's vertex or face colours), with the fields
//! `material::params` defines for both front-ends (Mitsuba 3's names,
//! meanings and defaults); texture coordinates of the spheres and disks.

use super::build::Builder;
use super::defs::Entry;
use super::shape::StepDef;
use super::SceneError;
use crate::material::params;
use crate::texture::{Bitmap, Filter, SurfaceUv, Texture, Wrap};
use glam::{Affine2, Affine3A, DAffine3, DVec3, Vec2, Vec3};
use std::path::Path;
use std::sync::Arc;
use toml::de::DeValue;
use toml::Spanned;

impl<'a> Builder<'a> {
    /// A texture parameter's value: a texture's name or an inline table.
    pub(super) fn texture_value(&mut self, v: Spanned<DeValue<'a>>, field: String) -> Result<u32, SceneError> {
        let span = v.span();
        if let DeValue::String(_) = v.get_ref() {
            let name: String = self.src.read(v, &field)?;
            if let Some(&t) = self.texture_names.get(&name) {
                return Ok(t);
            }
            if self.pending_textures.contains_key(&name) {
                return self.define_texture(&name);
            }
            let known: Vec<&str> =
                self.texture_names.keys().chain(self.pending_textures.keys()).map(String::as_str).collect();
            return self.fail(span, &field, format!("no texture named \"{name}\" (defined: {})", known.join(", ")));
        }
        let mut entry = Entry::new(&self.src, field, v)?;
        self.texture(&mut entry)
    }

    /// Builds the pending texture `name` and gives its index.
    pub(super) fn define_texture(&mut self, name: &str) -> Result<u32, SceneError> {
        if let Some(&t) = self.texture_names.get(name) {
            return Ok(t);
        }
        let Some(mut entry) = self.pending_textures.remove(name) else {
            return self.fail(0..0, name, "no such texture");
        };
        let t = self.texture(&mut entry)?;
        self.texture_names.insert(name.to_string(), t);
        Ok(t)
    }

    /// A texture table: its index among the scene's textures.
    fn texture(&mut self, entry: &mut Entry<'a>) -> Result<u32, SceneError> {
        let kind = entry.kind.get_ref().clone();
        let texture = match kind.as_str() {
            "bitmap" => {
                let mut f = self.fields(entry, &[params::BITMAP])?;
                let field = f.field("filename");
                let Some(v) = f.take("filename") else {
                    let (span, field) = (f.kind_span.clone(), f.field("filename"));
                    return self.fail(span, &field, "missing field `filename` (required for type \"bitmap\")");
                };
                let span = v.span();
                let name: String = self.src.read(v, &field)?;
                let filter = match self.choice(&mut f, &params::BITMAP[1])?.as_deref() {
                    Some("nearest") => Filter::Nearest,
                    _ => Filter::Bilinear,
                };
                let wrap = match self.choice(&mut f, &params::BITMAP[2])?.as_deref() {
                    Some("mirror") => Wrap::Mirror,
                    Some("clamp") => Wrap::Clamp,
                    _ => Wrap::Repeat,
                };
                let raw = self.flag(&mut f, "raw")?;
                let to_uv = self.to_uv(&mut f)?;
                let path = self.src.path.parent().unwrap_or(Path::new(".")).join(&name);
                let mut image = Bitmap::load(&path, raw)
                    .map_err(|e| self.src.error(span, field, format!("{}: {e}", path.display())))?;
                image.filter = filter;
                image.wrap = wrap;
                Texture::Bitmap { image: Arc::new(image), to_uv }
            }
            "checkerboard" => {
                let mut f = self.fields(entry, &[params::CHECKERBOARD])?;
                let color0 = self.param(&mut f, &params::CHECKERBOARD[0])?.mean(&[]);
                let color1 = self.param(&mut f, &params::CHECKERBOARD[1])?.mean(&[]);
                let to_uv = self.to_uv(&mut f)?;
                Texture::Checkerboard { color0, color1, to_uv }
            }
            "mesh_attribute" => {
                let mut f = self.fields(entry, &[params::MESH_ATTRIBUTE])?;
                let field = f.field("name");
                let Some(v) = f.take("name") else {
                    return self.fail(
                        f.kind_span.clone(),
                        &field,
                        "missing field `name` (required for type \"mesh_attribute\")",
                    );
                };
                let span = v.span();
                let name: String = self.src.read(v, &field)?;
                params::attribute_name(&name).map_err(|m| self.src.error(span, field, m))?;
                let scale = self.param(&mut f, &params::MESH_ATTRIBUTE[1])?.mean(&[]).x;
                // Its values once the meshes are read (`Builder::build`).
                self.attribute_textures.push((self.textures.len() as u32, name, scale));
                Texture::Attribute { values: Arc::new(Vec::new()), scale }
            }
            other => {
                let kind = entry.kind();
                return self.fail(
                    kind.span.clone(),
                    &kind.field,
                    format!("unknown texture type \"{other}\" (bitmap, checkerboard, mesh_attribute)"),
                );
            }
        };
        self.textures.push(texture);
        Ok(self.textures.len() as u32 - 1)
    }

    /// A texture's `to_uv`: transform steps, of which the 2D part is
    /// taken (the upper-left 2x2 block and the x, y translation, as
    /// Mitsuba takes it).
    fn to_uv(&self, f: &mut super::bsdf::Fields<'a>) -> Result<Affine2, SceneError> {
        let field = f.field("to_uv");
        let Some(v) = f.take("to_uv") else { return Ok(Affine2::IDENTITY) };
        let steps: Vec<Spanned<StepDef>> = self.src.read(v, &field)?;
        let m = self.transform(&field, &Some(steps))?;
        let (x, y, o) = (m.matrix3.x_axis, m.matrix3.y_axis, m.translation);
        Ok(Affine2::from_cols(Vec2::new(x.x, x.y), Vec2::new(y.x, y.y), Vec2::new(o.x, o.y)))
    }

    /// Records the texture coordinates of primitive `prim` (a sphere's or
    /// a disk's, about the frame `to_world`), computed as the Mitsuba
    /// front-end computes them from the same shape.
    pub(super) fn surface(&mut self, prim: usize, to_world: DAffine3, uv: fn(u32) -> SurfaceUv) {
        let inverse = to_world.inverse();
        self.frames.push(Affine3A::from_mat3_translation(inverse.matrix3.as_mat3(), inverse.translation.as_vec3()));
        self.surface_uv(prim, uv(self.frames.len() as u32 - 1));
    }

    /// Records the texture coordinates of primitive `prim`.
    pub(super) fn surface_uv(&mut self, prim: usize, uv: SurfaceUv) {
        if self.surfaces.len() <= prim {
            self.surfaces.resize(prim + 1, SurfaceUv::Barycentric);
        }
        self.surfaces[prim] = uv;
    }
}

/// A disk's frame: Mitsuba's unit disk (normal +z) placed as the Mitsuba
/// export writes it.
pub(super) fn disk_frame(d: &crate::shape::Disk) -> DAffine3 {
    written_affine(&d.to_world())
}

/// An ellipsoid's frame: Mitsuba's unit sphere under the transform the
/// Mitsuba export writes (`to_world`, or centre and radius where it only
/// moves and scales), so that its texture coordinates are a `sphere`'s.
pub(super) fn ellipsoid_frame(e: &crate::shape::Ellipsoid) -> DAffine3 {
    written_affine(&e.to_world())
}

/// A transform as the Mitsuba export writes it (`export::mitsuba::matrix`)
/// and the Mitsuba front-end reads it back.
fn written_affine(m: &glam::Affine3A) -> DAffine3 {
    let col = |v: glam::Vec3A| DVec3::new(written(v.x), written(v.y), written(v.z));
    DAffine3 {
        matrix3: glam::DMat3::from_cols(col(m.matrix3.x_axis), col(m.matrix3.y_axis), col(m.matrix3.z_axis)),
        translation: col(m.translation),
    }
}

/// A sphere's frame: Mitsuba's unit sphere moved and scaled.
pub(super) fn sphere_frame(center: Vec3, radius: f32) -> DAffine3 {
    let c = DVec3::new(written(center.x), written(center.y), written(center.z));
    DAffine3::from_translation(c) * DAffine3::from_scale(DVec3::splat(written(radius)))
}

/// A number as a scene file writes it (its shortest decimal form, which
/// the Mitsuba export writes too) read in double precision, as the Mitsuba
/// front-end reads it: the frames, and so the texture coordinates, are
/// the same from either file.
fn written(x: f32) -> f64 {
    x.to_string().parse().unwrap_or(x as f64)
}
