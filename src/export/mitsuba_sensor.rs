//! The camera as a Mitsuba 3 sensor: a pinhole as `perspective`, a thin
//! lens as `thinlens`, an orthographic camera as `orthographic`, each with
//! the film and sampler the exported scene's parameters set. Mitsuba's
//! image is a rectangle of square pixels seen unmirrored; its thin lens has
//! no principal point offset. What it cannot show is refused with the
//! reason.

use super::mitsuba::{matrix, xyz, Placement};
use crate::camera::{Camera, Projection};
use glam::{Affine3A, Vec3};
use std::fmt::Write;

/// The film and sampler every exported sensor ends with.
const FILM: &str = "        <sampler type=\"independent\"><integer name=\"sample_count\" value=\"$spp\"/><integer name=\"seed\" value=\"$seed\"/></sampler>\n\
     \x20       <film type=\"hdrfilm\"><integer name=\"width\" value=\"$width\"/><integer name=\"height\" value=\"$height\"/>\
     <string name=\"pixel_format\" value=\"rgb\"/><string name=\"component_format\" value=\"float32\"/><rfilter type=\"box\"/></film>\n    </sensor>\n";

/// The camera as a Mitsuba sensor, or why it cannot be one; placed by
/// `placement`.
pub(super) fn sensor(camera: &Camera, placement: Placement) -> Result<String, String> {
    let (upper_left, across, down) = camera.plane();
    let (w, h) = (camera.width as f32, camera.height as f32);
    let (la, ld) = (across.length(), down.length());
    if !(la > 0.0 && ld > 0.0) || across.dot(down).abs() > 1e-4 * la * ld {
        return Err("the image plane is not a rectangle, which a Mitsuba 3 camera cannot show".into());
    }
    if ((la / w) / (ld / h) - 1.0).abs() > 1e-4 {
        return Err(format!(
            "its pixels are not square ({:.6} x {:.6} scene units on the image plane at {}x{}); Mitsuba 3's are: \
             give the image the plane's aspect ratio",
            la / w,
            ld / h,
            camera.width,
            camera.height
        ));
    }
    if let Projection::Orthographic { dir } = camera.projection {
        return Ok(orthographic(upper_left, across, down, dir, placement));
    }
    let mut forward = across.cross(down).normalize();
    let mut distance = (upper_left - camera.eye).dot(forward);
    if distance < 0.0 {
        forward = -forward;
        distance = -distance;
    }
    if !(distance > 0.0) {
        return Err("the eye lies in the image plane".into());
    }
    let up = -down / ld;
    // Mitsuba's image runs along forward x up; a plane seen the other way
    // round is a mirror image, which it cannot show.
    if forward.cross(up).dot(across) <= 0.0 {
        return Err("the image plane is seen mirrored from the eye, which a Mitsuba 3 camera cannot show".into());
    }
    let foot = camera.eye + distance * forward;
    let fx = (foot - upper_left).dot(across) / (la * la);
    let fy = (foot - upper_left).dot(down) / (ld * ld);
    let fov = 2.0 * (0.5 * la / distance).atan().to_degrees();
    let mut own = String::new();
    let centred = (fx - 0.5).abs() <= 1e-6 && (fy - 0.5).abs() <= 1e-6;
    let kind = match camera.projection {
        Projection::ThinLens { radius, focus } => {
            if !centred {
                return Err(format!(
                    "the eye is off the image plane's centre (at {fx:.4}, {fy:.4} of it), which Mitsuba 3's thinlens \
                     cannot show (it has no principal point offset)"
                ));
            }
            let _ = writeln!(own, "        <float name=\"aperture_radius\" value=\"{}\"/>", radius * placement.scale);
            let _ = writeln!(own, "        <float name=\"focus_distance\" value=\"{}\"/>", focus * placement.scale);
            "thinlens"
        }
        _ => {
            if (fx - 0.5).abs() > 1e-6 {
                let _ = writeln!(own, "        <float name=\"principal_point_offset_x\" value=\"{}\"/>", 0.5 - fx);
            }
            if (fy - 0.5).abs() > 1e-6 {
                let _ = writeln!(own, "        <float name=\"principal_point_offset_y\" value=\"{}\"/>", 0.5 - fy);
            }
            "perspective"
        }
    };
    Ok(format!(
        "    <sensor type=\"{kind}\">\n        <string name=\"fov_axis\" value=\"x\"/>\n        <float name=\"fov\" value=\"{fov}\"/>\n{own}\
         \x20       <float name=\"near_clip\" value=\"{}\"/>\n        <float name=\"far_clip\" value=\"{}\"/>\n\
         \x20       <transform name=\"to_world\"><lookat origin=\"{}\" target=\"{}\" up=\"{}\"/></transform>\n{FILM}",
        1e-4 * distance * placement.scale,
        1e7 * distance * placement.scale,
        xyz(placement.point(camera.eye)),
        xyz(placement.point(camera.eye) + forward),
        xyz(up)
    ))
}

/// Mitsuba's orthographic sensor spans x in [-1, 1] (+x at the image's
/// left) and y in [-1/a, 1/a] of its frame, a the width over the height,
/// and starts its rays at z = near_clip: the frame's x axis is minus half
/// the plane's width, its y axis minus half its height times a, and its
/// origin lies near_clip behind the plane's centre along the rays
/// (include/mitsuba/render/sensor.h, `orthographic_projection`).
fn orthographic(upper_left: Vec3, across: Vec3, down: Vec3, dir: Vec3, placement: Placement) -> String {
    let s = placement.scale;
    let aspect = across.length() / down.length();
    let width = across.length() * s;
    let near = 1e-2 * width;
    let centre = placement.point(upper_left + 0.5 * across + 0.5 * down);
    let frame = Affine3A::from_cols(
        (-0.5 * s * across).into(),
        (-0.5 * s * aspect * down).into(),
        dir.into(),
        (centre - near * dir).into(),
    );
    format!(
        "    <sensor type=\"orthographic\">\n        <float name=\"near_clip\" value=\"{near}\"/>\n        \
         <float name=\"far_clip\" value=\"{}\"/>\n        {}\n{FILM}",
        1e7 * width,
        matrix(&frame)
    )
}
