//! Mitsuba's `principled` and `principledthin` BSDFs (src/bsdfs/principled.cpp,
//! principledthin.cpp) read as recipes: every parameter Mitsuba lets a
//! texture give may be one; a fixed weight must lie in the range Mitsuba
//! documents ([0, 1]; `diff_trans` [0, 2]); the sampling rates must be
//! positive (a lobe never sampled would be missed by the paths that go on
//! from it).

use super::props::Plugin;
use super::spectrum::Use;
use super::Builder;
use crate::material::disney::Rates;
use crate::material::{Param, Principled, PrincipledRecipe, Textured, ThinRecipe};
use crate::math::Color;
use crate::scene::file::SceneError;

impl Builder<'_> {
    /// A weight: a number within [lo, hi] or a texture.
    fn weight(&mut self, p: &Plugin, name: &str, default: f32, hi: f32) -> Result<Param, SceneError> {
        let param = self.param(p, name, Use::Unbounded, Color::splat(default))?;
        if let Param::Fixed(c) = param {
            if !(0.0..=hi).contains(&c.x) {
                let loc = p.named_loc(name);
                return Err(p.fail(&loc, name, format!("must lie in [0, {hi}], got {}", c.x)));
            }
        }
        Ok(param)
    }

    /// Sampling rates by name, interned.
    fn rates(p: &Plugin, names: &[&str]) -> Result<Rates, SceneError> {
        let mut rates = [1.0f32; 4];
        for (r, name) in rates.iter_mut().zip(names) {
            let v = p.float_or(name, 1.0)?;
            if !(v > 0.0 && v < 1e6) {
                let loc = p.named_loc(name);
                return Err(p.fail(&loc, name, format!("must be > 0 (and finite), got {v}")));
            }
            *r = v as f32;
        }
        Rates::intern(rates).ok_or_else(|| p.refuse("more than 255 different sets of sampling rates in one scene"))
    }

    pub(super) fn principled(&mut self, p: &Plugin) -> Result<Textured, SceneError> {
        // Mitsuba's `get_flag`: given, and not the number 0.
        let has_spec_trans = p.tag_of("spec_trans").is_some() && p.float("spec_trans").ok().flatten() != Some(0.0);
        let eta = match (p.tag_of("eta"), p.tag_of("specular")) {
            (Some(_), Some(_)) => return Err(p.refuse("give either eta or specular, not both (as in Mitsuba)")),
            (Some(_), None) => {
                let eta = p.float_in("eta", 1.5, 1e-3, 100.0)? as f32;
                if has_spec_trans && eta == 1.0 {
                    1.001
                } else {
                    eta
                }
            }
            (None, _) => {
                let specular = p.float_in("specular", 0.5, 0.0, 1.0)? as f32;
                let specular = if has_spec_trans && specular == 0.0 { 1e-3 } else { specular };
                Principled::eta_of_specular(specular)
            }
        };
        let recipe = PrincipledRecipe {
            base_color: self.reflectance(p, "base_color", 0.5)?,
            roughness: self.weight(p, "roughness", 0.5, 1.0)?,
            anisotropic: self.weight(p, "anisotropic", 0.0, 1.0)?,
            metallic: self.weight(p, "metallic", 0.0, 1.0)?,
            spec_trans: self.weight(p, "spec_trans", 0.0, 1.0)?,
            spec_tint: self.weight(p, "spec_tint", 0.0, 1.0)?,
            sheen: self.weight(p, "sheen", 0.0, 1.0)?,
            sheen_tint: self.weight(p, "sheen_tint", 0.0, 1.0)?,
            flatness: self.weight(p, "flatness", 0.0, 1.0)?,
            clearcoat: self.weight(p, "clearcoat", 0.0, 1.0)?,
            clearcoat_gloss: self.weight(p, "clearcoat_gloss", 0.0, 1.0)?,
            eta,
            rates: Self::rates(
                p,
                &["diffuse_reflectance_sampling_rate", "main_specular_sampling_rate", "clearcoat_sampling_rate"],
            )?,
        };
        p.finish(
            "base_color, roughness, anisotropic, metallic, spec_trans, eta, specular, spec_tint, sheen, sheen_tint, \
             flatness, clearcoat, clearcoat_gloss, diffuse_reflectance_sampling_rate, main_specular_sampling_rate, \
             clearcoat_sampling_rate",
        )?;
        Ok(Textured::Principled(recipe))
    }

    pub(super) fn principled_thin(&mut self, p: &Plugin) -> Result<Textured, SceneError> {
        let eta = self.param(p, "eta", Use::Unbounded, Color::splat(1.5))?;
        if let Param::Fixed(c) = eta {
            if !(c.x > 0.0 && c.x < 100.0) {
                return Err(p.fail(&p.named_loc("eta"), "eta", format!("must lie in (0, 100), got {}", c.x)));
            }
        }
        let recipe = ThinRecipe {
            base_color: self.reflectance(p, "base_color", 0.5)?,
            roughness: self.weight(p, "roughness", 0.5, 1.0)?,
            anisotropic: self.weight(p, "anisotropic", 0.0, 1.0)?,
            spec_trans: self.weight(p, "spec_trans", 0.0, 1.0)?,
            eta,
            spec_tint: self.weight(p, "spec_tint", 0.0, 1.0)?,
            sheen: self.weight(p, "sheen", 0.0, 1.0)?,
            sheen_tint: self.weight(p, "sheen_tint", 0.0, 1.0)?,
            flatness: self.weight(p, "flatness", 0.0, 1.0)?,
            diff_trans: self.weight(p, "diff_trans", 0.0, 2.0)?,
            rates: Self::rates(
                p,
                &[
                    "specular_reflectance_sampling_rate",
                    "specular_transmittance_sampling_rate",
                    "diffuse_transmittance_sampling_rate",
                    "diffuse_reflectance_sampling_rate",
                ],
            )?,
        };
        p.finish(
            "base_color, roughness, anisotropic, spec_trans, eta, spec_tint, sheen, sheen_tint, flatness, diff_trans, \
             specular_reflectance_sampling_rate, specular_transmittance_sampling_rate, \
             diffuse_transmittance_sampling_rate, diffuse_reflectance_sampling_rate",
        )?;
        Ok(Textured::PrincipledThin(recipe))
    }
}
