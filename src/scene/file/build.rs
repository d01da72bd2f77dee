//! A scene file's structure checked and turned into [`SceneParts`]: every
//! value in range, every name defined, every field one its type uses.

use super::defs::*;
use super::locate::Source;
use super::{SceneError, SceneFile};
use crate::material::Material;
use crate::math::Color;
use crate::scene::{LightSpec, Prim, SceneParts};
use glam::Vec3;
use std::collections::BTreeMap;
use std::ops::Range;
use toml::Spanned;

/// Builds the scene from its checked structure.
pub fn build(src: Source, def: FileDef) -> Result<SceneFile, SceneError> {
    Builder {
        src,
        materials: Vec::new(),
        names: BTreeMap::new(),
        prims: Vec::new(),
        shading_normals: Vec::new(),
        lights: Vec::new(),
        not_physical: Vec::new(),
        meshes: Vec::new(),
        origins: super::Origins { path: src.path.to_path_buf(), ..Default::default() },
    }
    .build(def)
}

pub(super) struct Builder<'a> {
    pub(super) src: Source<'a>,
    pub(super) materials: Vec<Material>,
    pub(super) names: BTreeMap<String, u32>,
    pub(super) prims: Vec<Prim>,
    pub(super) shading_normals: Vec<[Vec3; 3]>,
    pub(super) lights: Vec<LightSpec>,
    pub(super) not_physical: Vec<SceneError>,
    pub(super) meshes: Vec<std::path::PathBuf>,
    pub(super) origins: super::Origins,
}

/// A value with its span and its place in the file, for checks.
pub(super) struct At<'v, T> {
    pub(super) value: &'v T,
    pub(super) span: Range<usize>,
    pub(super) field: String,
}

pub(super) fn at<'v, T>(s: &'v Spanned<T>, field: String) -> At<'v, T> {
    At { value: s.get_ref(), span: s.span(), field }
}

impl Builder<'_> {
    pub(super) fn fail<T>(&self, span: Range<usize>, field: &str, message: impl Into<String>) -> Result<T, SceneError> {
        Err(self.src.error(span, field, message))
    }

    pub(super) fn finite(&self, v: &At<V3>) -> Result<Vec3, SceneError> {
        let x = Vec3::from_array(*v.value);
        if !x.is_finite() {
            return self.fail(v.span.clone(), &v.field, format!("must be finite, got {x}"));
        }
        Ok(x)
    }

    pub(super) fn color(&self, v: &At<V3>) -> Result<Color, SceneError> {
        let c = self.finite(v)?;
        if c.min_element() < 0.0 {
            return self.fail(v.span.clone(), &v.field, format!("must not be negative, got {c}"));
        }
        Ok(c)
    }

    pub(super) fn direction(&self, v: &At<V3>) -> Result<Vec3, SceneError> {
        let d = self.finite(v)?;
        d.try_normalize().ok_or_else(|| self.src.error(v.span.clone(), &v.field, "must not be the zero vector"))
    }

    pub(super) fn number(&self, v: &At<f32>, lo: f32, hi: f32, open_lo: bool) -> Result<f32, SceneError> {
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
    pub(super) fn need<'v, T>(
        &self,
        v: &'v Option<Spanned<T>>,
        owner: &At<String>,
        name: &str,
    ) -> Result<At<'v, T>, SceneError> {
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
    pub(super) fn reject(
        &self,
        owner: &At<String>,
        present: &[(&str, Option<Range<usize>>)],
    ) -> Result<(), SceneError> {
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
            let place = self.place(m.get_ref().kind.span(), format!("materials.{name}"));
            self.origins.materials.push(place);
            self.names.insert(name.clone(), self.materials.len() as u32 - 1);
        }
        for (i, s) in def.shapes.iter().enumerate() {
            let place = self.place(s.get_ref().kind.span(), format!("shapes[{i}]"));
            self.origins.objects.push(place);
            self.shape(i, s)?;
        }
        for (i, l) in def.lights.iter().enumerate() {
            self.light(i, l)?;
            let place = self.place(l.get_ref().kind.span(), format!("lights[{i}]"));
            self.origins.lights.push(place);
        }
        self.origins.camera = self.place(def.camera.span(), "camera".to_string());
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
        let parts = SceneParts {
            prims: self.prims,
            shading_normals: self.shading_normals,
            materials: self.materials,
            lights: self.lights,
            ambient,
            camera,
        };
        Ok(SceneFile {
            parts,
            origins: self.origins,
            rays_per_pixel_edge,
            not_physical: self.not_physical,
            meshes: self.meshes,
        })
    }

    /// Where the text at `span` is, as a [`super::Place`].
    fn place(&self, span: Range<usize>, field: String) -> super::Place {
        let e = self.src.error(span, field, "");
        super::Place { line: e.line, column: e.column, field: e.field }
    }
}
