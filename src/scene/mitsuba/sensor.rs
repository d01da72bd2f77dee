//! `<sensor>`, its `<film>`, reconstruction filter and sampler, as the
//! course's camera: an eye and the image plane's corners.
//!
//! Mitsuba's perspective camera looks along +z of its `to_world` frame
//! (whose x axis points to the image's left and y up, as its `lookat`
//! builds it); its field of view is `fov` across the axis `fov_axis`
//! names, at a plane at distance 1; a crop window and a principal point
//! offset move the rendered window on that plane (src/sensors/perspective.cpp,
//! src/render/sensor.cpp: `parse_fov`, `perspective_projection`).

use super::props::Plugin;
use crate::camera::Camera;
use crate::filter::Filter;
use crate::scene::file::SceneError;
use glam::{DVec3, Vec3};

/// The camera, the samples per pixel its sampler asks for, and the far
/// clip distance (which the scene's builder checks lies beyond everything).
pub fn camera(p: &Plugin) -> Result<(Camera, u32, f64), SceneError> {
    if p.kind != "perspective" {
        return Err(p.refuse(format!(
            "the '{}' sensor is not supported (perspective is; thinlens and orthographic are not yet)",
            p.kind
        )));
    }
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
    let spp = match p.object("sampler")? {
        None => 4,
        Some(s) => {
            // Every sampler gives an unbiased pixel estimate; photonmap uses
            // its own stratified sequence and takes only the count.
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
            n as u32
        }
    };

    let aspect = width as f64 / height as f64;
    let x_fov = fov(p, aspect)?;
    let to_world = p.transform("to_world")?.unwrap_or(glam::DAffine3::IDENTITY);
    let m = to_world.matrix3;
    let (left, up, dir) = (m.x_axis, m.y_axis, m.z_axis);
    let scaled = [left, up, dir].iter().any(|a| (a.length() - 1.0).abs() > 1e-4)
        || left.dot(up).abs() > 1e-4
        || left.dot(dir).abs() > 1e-4
        || up.dot(dir).abs() > 1e-4;
    if scaled {
        return Err(p.fail(
            p.loc(),
            "to_world",
            "scale factors in the camera's transform are not allowed (as in Mitsuba)",
        ));
    }
    let near = p.float_in("near_clip", 1e-2, 0.0, 1e15)?;
    let far = p.float_in("far_clip", 1e4, 0.0, f64::MAX)?;
    if !(far > near) {
        return Err(p.fail(p.loc(), "far_clip", format!("must exceed near_clip ({near}), got {far}")));
    }
    let ppo = (p.float_or("principal_point_offset_x", 0.0)?, p.float_or("principal_point_offset_y", 0.0)?);
    p.finish("fov, fov_axis, to_world, near_clip, far_clip, principal_point_offset_x, principal_point_offset_y, film, sampler")?;

    let eye = to_world.translation;
    let tx = (0.5 * x_fov.to_radians()).tan();
    let ty = tx / aspect;
    // A point of the full film in [0, 1]^2 (y down) on the plane at distance 1.
    let plane = |sx: f64, sy: f64| -> DVec3 { eye + dir + (1.0 - 2.0 * sx) * tx * left + (1.0 - 2.0 * sy) * ty * up };
    let (x0, y0) = (crop_x as f64 / width as f64 + ppo.0, crop_y as f64 / height as f64 + ppo.1);
    let (x1, y1) = (x0 + crop_w as f64 / width as f64, y0 + crop_h as f64 / height as f64);
    let v = |d: DVec3| -> Vec3 { d.as_vec3() };
    let (ul, ur, ll, lr) = (plane(x0, y0), plane(x1, y0), plane(x0, y1), plane(x1, y1));
    let mut camera = Camera::from_corners(v(eye), [v(lr), v(ll), v(ul), v(ur)], crop_w as u32, crop_h as u32);
    camera.filter = filter;
    camera.near = near as f32;
    if let Some(problem) = camera.precision_problem() {
        return Err(p.fail(p.loc(), "to_world", problem));
    }
    Ok((camera, spp, far))
}

/// The horizontal field of view in degrees, from `fov` and `fov_axis`.
pub(super) fn fov(p: &Plugin, aspect: f64) -> Result<f64, SceneError> {
    let fov = p.float("fov")?;
    let focal = p.string("focal_length")?;
    let (fov, axis) = match (fov, focal) {
        (Some(_), Some((_, loc))) => return Err(p.fail(&loc, "focal_length", "give either fov or focal_length")),
        (Some(f), None) => {
            let axis = p.string("fov_axis")?.map_or("x".to_string(), |(a, _)| a.to_lowercase());
            let axis = match axis.as_str() {
                "smaller" => (if aspect > 1.0 { "y" } else { "x" }).to_string(),
                "larger" => (if aspect > 1.0 { "x" } else { "y" }).to_string(),
                _ => axis,
            };
            (f, axis)
        }
        (None, focal) => {
            let text = focal.map_or("50mm".to_string(), |(f, _)| f);
            let mm: f64 = text
                .trim_end_matches("mm")
                .parse()
                .ok()
                .filter(|v: &f64| *v > 0.0)
                .ok_or_else(|| p.fail(p.loc(), "focal_length", format!("'{text}' is not <x>mm")))?;
            // A 36 x 24 mm frame's diagonal.
            (2.0 * ((36.0f64 * 36.0 + 24.0 * 24.0).sqrt() / (2.0 * mm)).atan().to_degrees(), "diagonal".to_string())
        }
    };
    let half = |deg: f64| (0.5 * deg.to_radians()).tan();
    let x = match axis.as_str() {
        "x" => fov,
        "y" => 2.0 * (half(fov) * aspect).atan().to_degrees(),
        "diagonal" => {
            let width = 2.0 * half(fov) / (1.0 + 1.0 / (aspect * aspect)).sqrt();
            2.0 * (0.5 * width).atan().to_degrees()
        }
        a => return Err(p.fail(p.loc(), "fov_axis", format!("'{a}' is not one of x, y, diagonal, smaller, larger"))),
    };
    if !(x > 0.0 && x < 180.0) {
        return Err(p.fail(p.loc(), "fov", format!("the horizontal field of view must lie in (0, 180), got {x}")));
    }
    Ok(x)
}
