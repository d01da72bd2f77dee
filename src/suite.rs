//! The scene suite (scenes/suite/): the scenes every change is scored on,
//! each with its independent reference and the window that frames its
//! caustic, as `scenes/suite/suite.toml` lists them. The suite's runner
//! (`examples/suite.rs`) and its tests (`tests/suite.rs`) read it here.

use crate::film::Film;
use crate::metrics::{compare_images, compare_window, Comparison, Window};
use crate::output::read_exr;
use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    scene: Vec<EntryDef>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EntryDef {
    file: String,
    reference: String,
    caustic: WindowDef,
    #[serde(default)]
    caustic_reference: Option<String>,
    #[serde(default)]
    mitsuba: Option<PlacementDef>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlacementDef {
    origin: [f32; 3],
    scale: f32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WindowDef {
    rows: [u32; 2],
    cols: [u32; 2],
}

/// One scene of the suite.
#[derive(Clone, Debug)]
pub struct SuiteScene {
    /// The scene file's stem, e.g. `02-cornell`.
    pub name: String,
    pub scene: PathBuf,
    pub reference: PathBuf,
    /// The caustic window, in the reference's pixels.
    pub caustic: Window,
    /// A reference of the caustic window alone, with more samples, where
    /// the whole image's is too noisy to measure the window's error: it
    /// scores the window in its place.
    pub caustic_reference: Option<PathBuf>,
    /// Where the reference's Mitsuba scene puts its origin, and its scale
    /// (`photonmap export --origin --scale`), where not at the eye: Mitsuba's
    /// equal-time renders use the same.
    pub mitsuba_placement: Option<(glam::Vec3, f32)>,
}

/// The reference's own noise and how it was made, from the JSON beside it
/// (absent for references that come with none).
#[derive(Clone, Debug, Default)]
pub struct ReferenceInfo {
    pub spp: Option<u64>,
    /// Estimated RMSE of the reference itself, whole image and caustic window.
    pub noise: Option<f64>,
    pub caustic_noise: Option<f64>,
}

impl SuiteScene {
    pub fn load_reference(&self) -> Result<Film, String> {
        read_exr(&self.reference).map_err(|e| format!("{}: {e}", self.reference.display()))
    }

    /// The caustic window's own reference, if the scene has one.
    pub fn load_caustic_reference(&self) -> Result<Option<Film>, String> {
        self.caustic_reference.as_ref().map(|p| read_exr(p).map_err(|e| format!("{}: {e}", p.display()))).transpose()
    }

    /// The references loaded for scoring renders of this scene.
    pub fn scoring(&self) -> Result<Scoring, String> {
        Ok(Scoring {
            reference: self.load_reference()?,
            caustic_reference: self.load_caustic_reference()?,
            caustic: self.caustic.clone(),
            info: self.reference_info(),
        })
    }

    pub fn reference_info(&self) -> ReferenceInfo {
        let json = |path: &Path| -> Option<serde_json::Value> {
            serde_json::from_str(&std::fs::read_to_string(path.with_extension("json")).ok()?).ok()
        };
        let Some(v) = json(&self.reference) else {
            return ReferenceInfo::default();
        };
        let caustic_noise = match &self.caustic_reference {
            Some(crop) => json(crop).and_then(|c| c["noise_rmse"].as_f64()),
            None => v["windows"]["caustic"]["noise_rmse"].as_f64(),
        };
        ReferenceInfo { spp: v["spp"].as_u64(), noise: v["noise_rmse"].as_f64(), caustic_noise }
    }
}

/// A suite scene's references, loaded: what scores a render of it the
/// same way wherever it is scored (the suite's runner, the calibration).
pub struct Scoring {
    pub reference: Film,
    caustic_reference: Option<Film>,
    caustic: Window,
    pub info: ReferenceInfo,
}

/// A render scored against its scene's references.
pub struct Score {
    /// Against the whole reference; the caustic window against its own
    /// reference where the scene has one.
    pub comparison: Comparison,
    /// RMSE less the reference's own noise in quadrature ([`less_noise`]):
    /// the whole image and the caustic window.
    pub rmse: f64,
    pub caustic_rmse: f64,
}

impl Scoring {
    pub fn score(&self, film: &Film) -> Result<Score, String> {
        let mut c =
            compare_images(film, &self.reference, std::slice::from_ref(&self.caustic)).map_err(|e| e.to_string())?;
        if let Some(crop) = &self.caustic_reference {
            c.windows[0].1 = compare_window(film, c.factor, &self.caustic, crop).map_err(|e| e.to_string())?;
        }
        let rmse = less_noise(c.whole.rmse, self.info.noise, 3 * c.whole.pixels);
        let caustic_rmse = less_noise(c.windows[0].1.rmse, self.info.caustic_noise, 3 * c.windows[0].1.pixels);
        Ok(Score { comparison: c, rmse, caustic_rmse })
    }
}

/// The suite in `dir` (scenes/suite), in the manifest's order.
pub fn load(dir: &Path) -> Result<Vec<SuiteScene>, String> {
    let path = dir.join("suite.toml");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let m: Manifest = toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(m.scene
        .into_iter()
        .map(|e| SuiteScene {
            name: e.file.trim_end_matches(".toml").to_string(),
            scene: dir.join(&e.file),
            reference: dir.join(&e.reference),
            caustic: Window {
                name: "caustic".into(),
                rows: (e.caustic.rows[0], e.caustic.rows[1]),
                cols: (e.caustic.cols[0], e.caustic.cols[1]),
            },
            caustic_reference: e.caustic_reference.map(|r| dir.join(r)),
            mitsuba_placement: e.mitsuba.map(|p| (glam::Vec3::from(p.origin), p.scale)),
        })
        .collect())
}

/// An error measured against a noisy reference over `values` pixel
/// channels, less the reference's own noise in quadrature (the two are
/// independent); zero, not measurable, where the excess over the noise is
/// within what the noise estimate's own error could make it.
///
/// The noise is estimated from the difference of two halves of the
/// reference's passes, one value per pixel channel: its square has a
/// relative standard error of sqrt(2 / values) where those are Gaussian.
/// An excess of the measured square over the noise's within three of
/// those is not counted (the small light's caustic window once read
/// 0.0018 from 0.01908 against a noise of 0.01899, 384 pixels: within
/// a quarter of one). Where the reference's noise has heavy tails the true
/// standard error is larger; notes/suite.md gives the bounds.
pub fn less_noise(measured: f64, noise: Option<f64>, values: u64) -> f64 {
    let n2 = noise.unwrap_or(0.0).powi(2);
    let excess = measured * measured - n2;
    let margin = 3.0 * n2 * (2.0 / values.max(1) as f64).sqrt();
    if excess <= margin {
        return 0.0;
    }
    excess.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_error_near_the_references_noise_is_not_measured() {
        // 384 pixels' channels: a margin of 3 sqrt(2 / 1152) = 12.5% of the
        // noise's square.
        assert_eq!(less_noise(0.01908, Some(0.01899), 1152), 0.0);
        assert_eq!(less_noise(0.0106, Some(0.01), 1152), 0.0);
        assert!(less_noise(0.0107, Some(0.01), 1152) > 0.0);
        // The whole image, 40,000 pixels: 1.2%.
        assert!(less_noise(0.0102, Some(0.01), 120_000) > 0.0);
        assert!((less_noise(0.02, Some(0.01), 120_000) - 0.03f64.sqrt() / 10.0).abs() < 1e-12);
        assert_eq!(less_noise(0.02, None, 1), 0.02);
    }
}
