//! A sensor's `<film>` (its size, crop window, storage formats and
//! reconstruction filter) and its `<sampler>` (of which photonmap takes the
//! sample count): what every Mitsuba sensor shares.

use super::props::Plugin;
use crate::filter::Filter;
use crate::scene::file::SceneError;

/// The film as a camera needs it.
pub struct Film {
    /// The full film, in pixels.
    pub width: u32,
    pub height: u32,
    /// The rendered window: its offset and size in pixels.
    pub crop: (u32, u32, u32, u32),
    pub filter: Filter,
}

impl Film {
    /// The full film's width over its height (Mitsuba's projections use it,
    /// not the crop window's).
    pub fn aspect(&self) -> f64 {
        self.width as f64 / self.height as f64
    }

    /// The crop window as fractions of the full film: its top-left and
    /// bottom-right corners, y down.
    pub fn window(&self) -> ((f64, f64), (f64, f64)) {
        let (x, y, w, h) = self.crop;
        let (fw, fh) = (self.width as f64, self.height as f64);
        ((x as f64 / fw, y as f64 / fh), ((x + w) as f64 / fw, (y + h) as f64 / fh))
    }
}

/// The sensor's `<film>`: Mitsuba's hdrfilm, written as photonmap's EXR.
pub fn film(p: &Plugin) -> Result<Film, SceneError> {
    let film = p.object("film")?.ok_or_else(|| p.refuse("the sensor needs a <film>"))?;
    if film.kind != "hdrfilm" {
        return Err(film.refuse(format!("the '{}' film is not supported (hdrfilm is)", film.kind)));
    }
    let size = |name: &str, default: i64| -> Result<u32, SceneError> {
        let v = film.integer(name)?.unwrap_or(default);
        if !(1..=65536).contains(&v) {
            return Err(film.fail(film.loc(), name, format!("must be in [1, 65536], got {v}")));
        }
        Ok(v as u32)
    };
    // Mitsuba's hdrfilm defaults.
    let (width, height) = (size("width", 768)?, size("height", 576)?);
    let crop_x = film.integer("crop_offset_x")?.unwrap_or(0);
    let crop_y = film.integer("crop_offset_y")?.unwrap_or(0);
    let crop_w = film.integer("crop_width")?.unwrap_or(width as i64 - crop_x);
    let crop_h = film.integer("crop_height")?.unwrap_or(height as i64 - crop_y);
    if crop_x < 0
        || crop_y < 0
        || crop_w < 1
        || crop_h < 1
        || crop_x + crop_w > width as i64
        || crop_y + crop_h > height as i64
    {
        return Err(film.refuse(format!(
            "the crop window ({crop_x}, {crop_y}) + {crop_w}x{crop_h} does not lie in the {width}x{height} film"
        )));
    }
    // Storage formats of the written file: photonmap's EXR is always RGB
    // in 32-bit floats, which holds what any of them would.
    for name in ["pixel_format", "component_format", "file_format"] {
        if let Some((v, loc)) = film.string(name)? {
            let fine = match name {
                "pixel_format" => matches!(v.as_str(), "rgb" | "rgba"),
                "component_format" => matches!(v.as_str(), "float16" | "float32"),
                _ => v == "openexr",
            };
            if !fine {
                return Err(film.fail(
                    &loc,
                    name,
                    format!("'{v}' is not supported (photonmap writes RGB floats to EXR)"),
                ));
            }
        }
    }
    let filter = match film.object("rfilter")? {
        None => Filter::Gaussian { stddev: 0.5 },
        Some(f) => {
            let filter = match f.kind {
                "box" => Filter::Box,
                "tent" => Filter::Tent { radius: f.float_in("radius", 1.0, 1e-3, 64.0)? as f32 },
                "gaussian" => Filter::Gaussian { stddev: f.float_in("stddev", 0.5, 1e-3, 16.0)? as f32 },
                k => {
                    return Err(f.refuse(format!(
                    "the '{k}' filter is not supported (box, tent and gaussian are: photonmap places samples by the \
                         filter's distribution, which needs a filter that is nowhere negative)"
                )))
                }
            };
            f.finish("radius (tent), stddev (gaussian)")?;
            filter
        }
    };
    film.finish(
        "width, height, crop_offset_x, crop_offset_y, crop_width, crop_height, pixel_format, component_format, \
         file_format, rfilter",
    )?;
    let crop = (crop_x as u32, crop_y as u32, crop_w as u32, crop_h as u32);
    Ok(Film { width, height, crop, filter })
}

/// The samples per pixel the sensor's `<sampler>` asks for (Mitsuba's
/// default 4).
pub fn sample_count(p: &Plugin) -> Result<u32, SceneError> {
    let Some(s) = p.object("sampler")? else { return Ok(4) };
    // Every sampler gives an unbiased pixel estimate; photonmap uses its own
    // stratified sequence and takes only the count.
    if !matches!(s.kind, "independent" | "stratified" | "multijitter" | "orthogonal" | "ldsampler") {
        return Err(s.refuse(format!("the '{}' sampler is not known", s.kind)));
    }
    let n = s.integer("sample_count")?.unwrap_or(4);
    s.integer("seed")?;
    s.boolean("jitter", true)?;
    s.integer("strength")?;
    s.finish("sample_count, seed, jitter, strength")?;
    if !(1..=1 << 20).contains(&n) {
        return Err(s.fail(s.loc(), "sample_count", format!("must be in [1, {}], got {n}", 1 << 20)));
    }
    Ok(n as u32)
}
