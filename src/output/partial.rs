//! Partial renders: the exact sums of a set of progressive passes in an
//! EXR, with a manifest that says what they are sums of. Its R, G, B
//! channels hold the passes' average, so any viewer shows it; channels
//! `sums.00` to `sums.47` hold the fixed-point sums as 32-bit words
//! ([`crate::film::accumulation::PixelSums::words`]); the header
//! attribute `photonmap.manifest` holds the manifest as JSON.

use super::exr_file::{read_channels, write_channels, Samples};
use super::{atomically, check_writable, Format};
use crate::error::{Error, Result};
use crate::film::accumulation::{Accumulation, PassSet, PixelSums, WORDS};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// What a partial's sums are sums of. Two partials merge only if every
/// field but `passes` and `parts` is the same.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// The program and version that rendered the passes.
    pub program: String,
    /// The scene, as given (a file path, or the built-in room).
    pub scene: String,
    /// SHA-256 of the scene file and every mesh it reads.
    pub scene_hash: String,
    /// Every setting that changes pixels (seed and size included).
    pub settings: String,
    pub width: u32,
    pub height: u32,
    /// The estimator ("photon" or "path") and the radius schedule's alpha:
    /// what the error estimate needs.
    pub method: String,
    pub alpha: f32,
    /// The passes included ("0..4,8..12").
    pub passes: String,
    /// The runs that rendered them.
    pub parts: Vec<Part>,
}

/// One run's share of a partial.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Part {
    pub passes: String,
    /// Photons emitted (global and caustic).
    pub photons: u64,
    pub seconds: f64,
}

impl Manifest {
    /// Why a partial with manifest `other` cannot be added to one with
    /// this manifest (`None`: it can; overlapping passes are checked by
    /// the sums themselves).
    pub fn mismatch(&self, other: &Manifest) -> Option<String> {
        let differs = |what: &str, a: &dyn std::fmt::Display, b: &dyn std::fmt::Display| {
            Some(format!("{what} differ: {a} against {b}"))
        };
        if self.program != other.program {
            return differs("the programs", &self.program, &other.program);
        }
        if self.scene_hash != other.scene_hash {
            return differs(
                "the scenes",
                &format!("{} ({})", self.scene, short(&self.scene_hash)),
                &format!("{} ({})", other.scene, short(&other.scene_hash)),
            );
        }
        if (self.width, self.height) != (other.width, other.height) {
            return differs(
                "the image sizes",
                &format!("{}x{}", self.width, self.height),
                &format!("{}x{}", other.width, other.height),
            );
        }
        if self.method != other.method {
            return differs("the integrators", &self.method, &other.method);
        }
        if self.alpha != other.alpha {
            return differs("the alphas", &self.alpha, &other.alpha);
        }
        if self.settings != other.settings {
            return Some(format!("the settings differ: {}", settings_differences(&self.settings, &other.settings)));
        }
        None
    }
}

/// The fields in which two settings keys (`Settings { photons: 1000, seed:
/// 1, .. }`) differ, as `photons 1000 against 2000, seed 1 against 2`: a
/// reader is not left to find them in two long lines.
fn settings_differences(a: &str, b: &str) -> String {
    let (fa, fb) = (key_fields(a), key_fields(b));
    let mut out: Vec<String> = fa
        .iter()
        .filter_map(|(name, va)| match fb.iter().find(|(n, _)| n == name) {
            Some((_, vb)) if vb == va => None,
            Some((_, vb)) => Some(format!("{name} {va} against {vb}")),
            None => Some(format!("{name} {va} against none")),
        })
        .collect();
    out.extend(
        fb.iter().filter(|(n, _)| !fa.iter().any(|(m, _)| m == n)).map(|(n, v)| format!("{n} none against {v}")),
    );
    if out.is_empty() {
        // Not a key of fields: the two in full.
        return format!("{a} against {b}");
    }
    out.join(", ")
}

/// A settings key's `name: value` fields (commas inside brackets kept).
fn key_fields(key: &str) -> Vec<(String, String)> {
    let inner = key.find('{').zip(key.rfind('}')).map_or(key, |(i, j)| if i < j { &key[i + 1..j] } else { key });
    let (mut fields, mut depth, mut start) = (Vec::new(), 0i32, 0usize);
    let mut push = |part: &str| {
        if let Some((name, value)) = part.split_once(':') {
            fields.push((name.trim().to_string(), value.trim().to_string()));
        }
    };
    for (i, c) in inner.char_indices() {
        match c {
            '(' | '[' | '{' => depth += 1,
            ')' | ']' | '}' => depth -= 1,
            ',' if depth == 0 => {
                push(&inner[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    push(&inner[start..]);
    fields
}

fn short(hash: &str) -> &str {
    &hash[..hash.len().min(12)]
}

/// A partial render: its manifest and sums.
#[derive(Clone, Debug)]
pub struct Partial {
    pub manifest: Manifest,
    pub accumulation: Accumulation,
}

/// Writes a partial (atomically: a temporary file renamed over `path`).
pub fn write_partial(path: &Path, partial: &Partial) -> Result<()> {
    if check_writable(path)? != Format::Exr {
        return Err(Error::Invalid(format!("{}: a partial render is an .exr file", path.display())));
    }
    let acc = &partial.accumulation;
    let mut manifest = partial.manifest.clone();
    manifest.passes = acc.passes.to_string();
    let json = serde_json::to_string(&manifest).map_err(|e| Error::Invalid(e.to_string()))?;
    let average = acc.average();
    let mut channels: Vec<(String, Samples)> = Vec::with_capacity(3 + WORDS);
    for (c, name) in ["R", "G", "B"].into_iter().enumerate() {
        channels.push((name.into(), Samples::F32(average.pixels.iter().map(|p| p.to_array()[c]).collect())));
    }
    let words: Vec<[u32; WORDS]> = acc.pixels.iter().map(PixelSums::words).collect();
    for w in 0..WORDS {
        channels.push((format!("sums.{w:02}"), Samples::U32(words.iter().map(|p| p[w]).collect())));
    }
    atomically(path, |tmp| write_channels(tmp, acc.width, acc.height, channels, &[("manifest".into(), json)]))
}

/// Reads a partial, checking that it is one and that its sums and
/// manifest agree.
pub fn read_partial(path: &Path) -> Result<Partial> {
    let bad = |message: String| Error::Decode { path: path.to_owned(), message };
    let (header, channels) = read_channels(path)?;
    let json = header.get("manifest").ok_or_else(|| {
        bad("not a partial render (no photonmap.manifest attribute; write one with --partial)".into())
    })?;
    let manifest: Manifest = serde_json::from_str(json).map_err(|e| bad(format!("its manifest: {e}")))?;
    if (manifest.width, manifest.height) != (header.width, header.height) {
        return Err(bad(format!(
            "the manifest says {}x{}, the image is {}x{}",
            manifest.width, manifest.height, header.width, header.height
        )));
    }
    let passes = PassSet::parse(&manifest.passes).map_err(|e| bad(format!("its manifest's passes: {e}")))?;
    let n = header.width as usize * header.height as usize;
    let mut words: Vec<Option<Vec<u32>>> = vec![None; WORDS];
    for (name, samples) in channels {
        if let (Some(w), Samples::U32(v)) = (name.strip_prefix("sums.").and_then(|w| w.parse::<usize>().ok()), samples)
        {
            if w < WORDS && v.len() == n {
                words[w] = Some(v);
            }
        }
    }
    let words: Vec<Vec<u32>> = words
        .into_iter()
        .enumerate()
        .map(|(w, v)| v.ok_or_else(|| bad(format!("channel sums.{w:02} (32-bit integers) is missing"))))
        .collect::<Result<_>>()?;
    let pixels = (0..n)
        .map(|i| {
            let mut p = [0u32; WORDS];
            for (w, v) in words.iter().enumerate() {
                p[w] = v[i];
            }
            PixelSums::from_words(&p)
        })
        .collect();
    let accumulation = Accumulation { width: header.width, height: header.height, passes, pixels };
    Ok(Partial { manifest, accumulation })
}

/// Adds `parts` into one partial, in any order (the sums are exact, so the
/// order cannot change a bit). Refuses parts that do not belong together,
/// naming them: another scene, setting, size or program, passes given
/// twice, or (unless `allow_gaps`) passes missing before the last one.
pub fn merge(parts: &[(String, Partial)], allow_gaps: bool) -> Result<Partial> {
    let Some((first_name, first)) = parts.first() else {
        return Err(Error::Invalid("merge: no partial renders given".into()));
    };
    let mut merged = first.clone();
    for (name, part) in &parts[1..] {
        if let Some(why) = first.manifest.mismatch(&part.manifest) {
            return Err(Error::Invalid(format!("{name} does not belong with {first_name}: {why}")));
        }
        if let Err(overlap) = merged.accumulation.merge(&part.accumulation) {
            let with = parts
                .iter()
                .take_while(|(n, _)| n != name)
                .find(|(_, p)| p.accumulation.passes.iter().any(|i| overlap.contains(&i)))
                .map_or(first_name, |(n, _)| n);
            return Err(Error::Invalid(format!(
                "{name} and {with} both hold passes {}..{}",
                overlap.start, overlap.end
            )));
        }
        merged.manifest.parts.extend(part.manifest.parts.iter().cloned());
    }
    let passes = &merged.accumulation.passes;
    if !allow_gaps && !passes.is_prefix() {
        let ranges = passes.ranges();
        let missing = match ranges.first() {
            Some(r) if r.start > 0 => 0..r.start,
            _ => ranges[0].end..ranges[1].start,
        };
        return Err(Error::Invalid(format!(
            "passes {}..{} are missing (the parts hold {passes}); render them, or merge with --allow-gaps",
            missing.start, missing.end
        )));
    }
    merged.manifest.parts.sort_by_key(|p| PassSet::parse(&p.passes).ok().and_then(|s| s.iter().next()));
    merged.manifest.passes = passes.to_string();
    Ok(merged)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::provenance::settings_key;
    use crate::render::settings::Settings;

    #[test]
    fn differing_settings_are_named_field_by_field() {
        let a = Settings::default();
        let b = Settings { photons: a.photons * 2, seed: 7, r_global: Some(0.5), ..a };
        let why = settings_differences(&settings_key(&a), &settings_key(&b));
        let want = format!(
            "photons {} against {}, seed {} against 7, r_global None against Some(0.5)",
            a.photons, b.photons, a.seed
        );
        assert_eq!(why, want);
        assert_eq!(settings_differences("x", "y"), "x against y");
    }
}
