//! Mitsuba's `principled` and `principledthin` BSDFs (src/bsdfs/principled.cpp,
//! principledthin.cpp) read as recipes, by the parameters
//! `material::params` defines for both front-ends: every parameter
//! Mitsuba lets a texture give may be one; a fixed value must lie in its
//! range (weights in [0, 1], `diff_trans` [0, 2], sampling rates above 0:
//! a lobe never sampled would be missed by the paths that go on from it).

use super::props::Plugin;
use super::spectrum::Use;
use super::Builder;
use crate::material::disney::Rates;
use crate::material::params::{self, Spec};
use crate::material::{Param, PrincipledRecipe, Textured, ThinRecipe};
use crate::scene::file::SceneError;

impl Builder<'_> {
    /// A parameter by its definition: a number or colour in its range, or
    /// a texture where it may be one.
    pub(super) fn spec_param(&mut self, p: &Plugin, s: &Spec) -> Result<Param, SceneError> {
        let usage = if s.kind == params::Kind::Reflectance { Use::Reflectance } else { Use::Unbounded };
        let param = self.param(p, s.name, usage, s.default_color())?;
        if let Param::Fixed(c) = param {
            s.check(c).map_err(|m| p.fail(&p.named_loc(s.name), s.name, m))?;
        }
        Ok(param)
    }

    /// Sampling rates by their definitions, interned.
    fn rates(p: &Plugin, specs: &[Spec]) -> Result<Rates, SceneError> {
        let mut rates = [1.0f32; 4];
        for (r, s) in rates.iter_mut().zip(specs) {
            let v = p.float_or(s.name, s.default as f64)? as f32;
            s.check(crate::math::Color::splat(v)).map_err(|m| p.fail(&p.named_loc(s.name), s.name, m))?;
            *r = v;
        }
        Rates::intern(rates).ok_or_else(|| p.refuse("more than 255 different sets of sampling rates in one scene"))
    }

    fn spec_params<const N: usize>(&mut self, p: &Plugin, specs: &[Spec]) -> Result<[Param; N], SceneError> {
        let mut out = [Param::Fixed(crate::math::Color::ZERO); N];
        for (o, s) in out.iter_mut().zip(specs) {
            *o = self.spec_param(p, s)?;
        }
        Ok(out)
    }

    pub(super) fn principled(&mut self, p: &Plugin) -> Result<Textured, SceneError> {
        // Mitsuba's `get_flag`: given, and not the number 0.
        let has_spec_trans = p.tag_of("spec_trans").is_some() && p.float("spec_trans").ok().flatten() != Some(0.0);
        let [eta_spec, specular_spec] = [params::PRINCIPLED_ETA[0], params::PRINCIPLED_ETA[1]];
        let number = |s: &Spec| -> Result<Option<f32>, SceneError> {
            match p.float(s.name)? {
                None => Ok(None),
                Some(v) => {
                    s.check(crate::math::Color::splat(v as f32))
                        .map_err(|m| p.fail(&p.named_loc(s.name), s.name, m))?;
                    Ok(Some(v as f32))
                }
            }
        };
        if p.tag_of("eta").is_some() && p.tag_of("specular").is_some() {
            return Err(p.refuse("give either eta or specular, not both (as in Mitsuba)"));
        }
        let eta = params::principled_eta(number(&eta_spec)?, number(&specular_spec)?, has_spec_trans);
        let recipe = PrincipledRecipe::from_params(
            self.spec_params(p, params::PRINCIPLED)?,
            eta,
            Self::rates(p, params::PRINCIPLED_RATES)?,
        );
        p.finish(&names(&[params::PRINCIPLED, params::PRINCIPLED_ETA, params::PRINCIPLED_RATES]))?;
        Ok(Textured::Principled(recipe))
    }

    pub(super) fn principled_thin(&mut self, p: &Plugin) -> Result<Textured, SceneError> {
        let recipe = ThinRecipe::from_params(
            self.spec_params(p, params::PRINCIPLED_THIN)?,
            Self::rates(p, params::PRINCIPLED_THIN_RATES)?,
        );
        p.finish(&names(&[params::PRINCIPLED_THIN, params::PRINCIPLED_THIN_RATES]))?;
        Ok(Textured::PrincipledThin(recipe))
    }
}

/// The parameters' names, for a refusal's list.
fn names(lists: &[&[Spec]]) -> String {
    lists.iter().flat_map(|l| l.iter().map(|s| s.name)).collect::<Vec<_>>().join(", ")
}
