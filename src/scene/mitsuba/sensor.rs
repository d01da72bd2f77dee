//! `<sensor>`: Mitsuba 3's projective cameras as the course's camera, an
//! eye and the image plane's corners, with the projection that turns the
//! plane's points into rays.
//!
//! Mitsuba's cameras look along +z of their `to_world` frame (whose x axis
//! points to the image's left and y up, as its `lookat` builds it), and all
//! read `near_clip`, `far_clip` and `focus_distance` (default: far_clip;
//! src/render/sensor.cpp, `ProjectiveCamera`). A crop window of the film
//! picks part of the full film's view.
//!
//! - `perspective` and `thinlens`: the field of view is `fov` across the
//!   axis `fov_axis` names (or a 35 mm `focal_length`), at a plane at
//!   distance 1; `perspective` alone moves that window by a principal point
//!   offset (src/sensors/perspective.cpp, src/render/sensor.cpp:
//!   `parse_fov`, `perspective_projection`). `thinlens` adds a lens of
//!   radius `aperture_radius` (required) focused at `focus_distance`
//!   (src/sensors/thinlens.cpp). Neither allows scale in `to_world`.
//! - `orthographic`: rays leave the plane z = near_clip of the camera frame
//!   along its +z; the full film spans x in [-1, 1] and y in [-1/a, 1/a]
//!   (a the film's width over its height) before `to_world`, whose scale
//!   therefore sets the view's extent (src/sensors/orthographic.cpp,
//!   `orthographic_projection` in include/mitsuba/render/sensor.h).

use super::film::{film, sample_count, Film};
use super::props::Plugin;
use crate::camera::{Camera, Projection};
use crate::scene::file::SceneError;
use glam::{DAffine3, DVec3, Vec3};

/// What every sensor accepts beside its own parameters.
const COMMON: &str = "to_world, near_clip, far_clip, focus_distance, film, sampler";

/// The camera, the samples per pixel its sampler asks for, and how far its
/// rays reach from its eye (which the scene's builder checks lies beyond
/// everything: photonmap does not clip far geometry).
pub fn camera(p: &Plugin) -> Result<(Camera, u32, f64), SceneError> {
    if !matches!(p.kind, "perspective" | "thinlens" | "orthographic") {
        return Err(
            p.refuse(format!("the '{}' sensor is not supported (perspective, thinlens and orthographic are)", p.kind))
        );
    }
    let film = film(p)?;
    let spp = sample_count(p)?;
    let to_world = p.transform("to_world")?.unwrap_or(DAffine3::IDENTITY);
    let near = p.float_in("near_clip", 1e-2, 0.0, 1e15)?;
    let far = p.float_in("far_clip", 1e4, 0.0, f64::MAX)?;
    if !(far > near) {
        return Err(p.fail(&p.named_loc("far_clip"), "far_clip", format!("must exceed near_clip ({near}), got {far}")));
    }
    // Read by every projective camera in Mitsuba; only the thin lens uses it.
    let focus = p.float("focus_distance")?.unwrap_or(far);
    let (mut camera, reach) = match p.kind {
        "orthographic" => {
            p.finish(COMMON)?;
            (orthographic(p, &film, to_world, near)?, far - near)
        }
        _ => (perspective(p, &film, to_world, near, focus)?, far),
    };
    camera.filter = film.filter;
    if let Some(problem) = camera.precision_problem() {
        return Err(p.fail(p.loc(), "to_world", problem));
    }
    Ok((camera, spp, reach))
}

/// `perspective` and `thinlens`: an eye (or lens) at the frame's origin.
fn perspective(p: &Plugin, film: &Film, to_world: DAffine3, near: f64, focus: f64) -> Result<Camera, SceneError> {
    let x_fov = fov(p, film.aspect())?;
    let m = to_world.matrix3;
    let (left, up, dir) = (m.x_axis, m.y_axis, m.z_axis);
    let scaled = [left, up, dir].iter().any(|a| (a.length() - 1.0).abs() > 1e-4)
        || left.dot(up).abs() > 1e-4
        || left.dot(dir).abs() > 1e-4
        || up.dot(dir).abs() > 1e-4;
    if scaled {
        return Err(p.fail(
            &p.named_loc("to_world"),
            "to_world",
            "scale factors in the camera's transform are not allowed (as in Mitsuba)",
        ));
    }
    let (projection, ppo) = if p.kind == "thinlens" {
        let radius = p.float("aperture_radius")?.ok_or_else(|| {
            p.refuse(
                "the thinlens sensor needs aperture_radius (the lens's radius in scene units; Mitsuba has no default)",
            )
        })?;
        if !(0.0..=1e15).contains(&radius) {
            let loc = p.named_loc("aperture_radius");
            return Err(p.fail(&loc, "aperture_radius", format!("must be in [0, 1e15], got {radius}")));
        }
        if !(focus > 0.0 && focus <= 1e15) {
            let loc = p.named_loc("focus_distance");
            return Err(p.fail(
                &loc,
                "focus_distance",
                format!("must be in (0, 1e15] (its default is far_clip), got {focus}"),
            ));
        }
        p.finish(&format!("aperture_radius, fov, fov_axis, focal_length, {COMMON}"))?;
        // Mitsuba replaces a zero radius by the smallest float, a pinhole
        // to the last bit.
        let projection = if radius == 0.0 {
            Projection::Pinhole
        } else {
            Projection::ThinLens { radius: radius as f32, focus: focus as f32 }
        };
        (projection, (0.0, 0.0))
    } else {
        let ppo = (p.float_or("principal_point_offset_x", 0.0)?, p.float_or("principal_point_offset_y", 0.0)?);
        p.finish(&format!(
            "fov, fov_axis, focal_length, principal_point_offset_x, principal_point_offset_y, {COMMON}"
        ))?;
        (Projection::Pinhole, ppo)
    };

    let eye = to_world.translation;
    let tx = (0.5 * x_fov.to_radians()).tan();
    let ty = tx / film.aspect();
    // A point of the full film in [0, 1]^2 (y down) on the plane at distance 1.
    let plane = |sx: f64, sy: f64| -> DVec3 { eye + dir + (1.0 - 2.0 * sx) * tx * left + (1.0 - 2.0 * sy) * ty * up };
    let ((x0, y0), (x1, y1)) = film.window();
    let (x0, y0, x1, y1) = (x0 + ppo.0, y0 + ppo.1, x1 + ppo.0, y1 + ppo.1);
    let mut camera = corners(eye, [plane(x0, y0), plane(x1, y0), plane(x0, y1), plane(x1, y1)], film);
    camera.near = near as f32;
    camera.projection = projection;
    Ok(camera)
}

/// `orthographic`: rays along the frame's +z from its plane z = `near`.
fn orthographic(p: &Plugin, film: &Film, to_world: DAffine3, near: f64) -> Result<Camera, SceneError> {
    let m = to_world.matrix3;
    let volume = m.determinant().abs();
    if !(volume > 1e-12 * m.x_axis.length() * m.y_axis.length() * m.z_axis.length()) {
        return Err(p.fail(
            &p.named_loc("to_world"),
            "to_world",
            "the transform flattens the view (its axes are not independent): an orthographic sensor needs              an extent across, up and along the view",
        ));
    }
    let a = film.aspect();
    let plane = |sx: f64, sy: f64| -> DVec3 {
        to_world.transform_point3(DVec3::new(1.0 - 2.0 * sx, (1.0 - 2.0 * sy) / a, near))
    };
    let ((x0, y0), (x1, y1)) = film.window();
    let centre = plane(0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let mut camera = corners(centre, [plane(x0, y0), plane(x1, y0), plane(x0, y1), plane(x1, y1)], film);
    camera.projection = Projection::Orthographic { dir: m.z_axis.normalize().as_vec3() };
    Ok(camera)
}

/// The camera of the crop window whose corners are upper-left, upper-right,
/// lower-left, lower-right.
fn corners(eye: DVec3, [ul, ur, ll, lr]: [DVec3; 4], film: &Film) -> Camera {
    let v = |d: DVec3| -> Vec3 { d.as_vec3() };
    let (_, _, w, h) = film.crop;
    Camera::from_corners(v(eye), [v(lr), v(ll), v(ul), v(ur)], w, h)
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
