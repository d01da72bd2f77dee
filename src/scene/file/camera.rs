//! `[camera]`: the course's corner form or look-at, the image size, and an
//! optional thin lens (`aperture_radius`, `focus_distance`).

use super::build::{at, At, Builder, LIMIT};
use super::defs::V3;
use super::SceneError;
use crate::camera::{Camera, Projection};
use glam::Vec3;
use serde::Deserialize;
use std::ops::Range;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDef {
    pub eye: Spanned<V3>,
    pub lower_left: Option<Spanned<V3>>,
    pub lower_right: Option<Spanned<V3>>,
    pub upper_left: Option<Spanned<V3>>,
    pub upper_right: Option<Spanned<V3>>,
    pub target: Option<Spanned<V3>>,
    pub up: Option<Spanned<V3>>,
    pub vfov: Option<Spanned<f32>>,
    pub width: Spanned<i64>,
    pub height: Spanned<i64>,
    pub rays_per_pixel_edge: Option<Spanned<i64>>,
    pub aperture_radius: Option<Spanned<f32>>,
    pub focus_distance: Option<Spanned<f32>>,
    /// The participating medium the camera is in (`[media.NAME]`).
    pub medium: Option<Spanned<String>>,
}

impl Builder<'_> {
    pub(super) fn camera(&self, c: &Spanned<CameraDef>) -> Result<(Camera, u32), SceneError> {
        let d = c.get_ref();
        let f = |n: &str| format!("camera.{n}");
        let eye = self.finite(&at(&d.eye, f("eye")))?;
        let size = |v: &Spanned<i64>, n: &str| -> Result<u32, SceneError> {
            let x = *v.get_ref();
            if !(1..=65536).contains(&x) {
                return self.fail(v.span(), &f(n), format!("must be in [1, 65536], got {x}"));
            }
            Ok(x as u32)
        };
        let (width, height) = (size(&d.width, "width")?, size(&d.height, "height")?);
        let n = match &d.rays_per_pixel_edge {
            Some(v) => {
                let x = *v.get_ref();
                if !(1..=64).contains(&x) {
                    return self.fail(v.span(), &f("rays_per_pixel_edge"), format!("must be in [1, 64], got {x}"));
                }
                x as u32
            }
            None => 1,
        };
        let corners = [&d.lower_left, &d.lower_right, &d.upper_left, &d.upper_right];
        let look = [d.target.as_ref().map(|s| s.span()), d.up.as_ref().map(|s| s.span())];
        let camera = if corners.iter().any(|c| c.is_some()) {
            if let Some(span) = look.iter().flatten().next().cloned().or(d.vfov.as_ref().map(|s| s.span())) {
                return self.fail(span, "camera", "give either the four corners or target/up/vfov, not both");
            }
            let names = ["lower_left", "lower_right", "upper_left", "upper_right"];
            let mut p = [Vec3::ZERO; 4];
            for ((slot, c), name) in p.iter_mut().zip(corners).zip(names) {
                let Some(c) = c else {
                    return self.fail(
                        c_span(c, &d.eye),
                        &f(name),
                        format!("missing field `{name}` (all four corners are needed)"),
                    );
                };
                *slot = self.finite(&at(c, f(name)))?;
            }
            let [ll, lr, ul, ur] = p;
            // The corners must form a parallelogram the eye is not on.
            let err = ((lr - ll) - (ur - ul)).length();
            let size = (lr - ll).length().max((ul - ll).length());
            if !(size > 0.0) || err > 1e-4 * size || (ul - ll).cross(lr - ll).dot(ll - eye).abs() <= 1e-12 * size * size
            {
                return self.fail(
                    c.span(),
                    "camera",
                    "the corners must form a rectangle in a plane not through the eye",
                );
            }
            Camera::from_corners(eye, [lr, ll, ul, ur], width, height)
        } else {
            let target = self.finite(&self.need_cam(&d.target, c, "target")?)?;
            let up = self.direction(&self.need_cam(&d.up, c, "up")?)?;
            let vfov = self.number(&self.need_cam(&d.vfov, c, "vfov")?, 0.0, 179.0, true)?;
            let forward = (target - eye).try_normalize().ok_or_else(|| {
                self.src.error(
                    d.target.as_ref().map_or(c.span(), |t| t.span()),
                    f("target"),
                    "must differ from the eye",
                )
            })?;
            let right = forward.cross(up).try_normalize().ok_or_else(|| {
                self.src.error(
                    d.up.as_ref().map_or(c.span(), |t| t.span()),
                    f("up"),
                    "must not be parallel to the view direction",
                )
            })?;
            let true_up = right.cross(forward);
            let h = (vfov.to_radians() * 0.5).tan();
            let w = h * width as f32 / height as f32;
            let centre = eye + forward;
            let ll = centre - right * w - true_up * h;
            let lr = centre + right * w - true_up * h;
            let ul = centre - right * w + true_up * h;
            let ur = centre + right * w + true_up * h;
            Camera::from_corners(eye, [lr, ll, ul, ur], width, height).widening()
        };
        if let Some(problem) = camera.precision_problem() {
            return self.fail(d.eye.span(), &f("eye"), problem);
        }
        let camera = self.lens(c, camera)?;
        Ok((camera, n))
    }

    /// A thin lens of radius `aperture_radius` focused at `focus_distance`
    /// along the view (in the look-at form, the target's distance unless
    /// given); a radius of 0, or none, is the pinhole.
    fn lens(&self, c: &Spanned<CameraDef>, mut camera: Camera) -> Result<Camera, SceneError> {
        let d = c.get_ref();
        let radius = match &d.aperture_radius {
            Some(r) => self.number(&at(r, "camera.aperture_radius".into()), 0.0, LIMIT, false)?,
            None => 0.0,
        };
        let focus = match (&d.focus_distance, &d.target) {
            (Some(v), _) => self.number(&at(v, "camera.focus_distance".into()), 0.0, LIMIT, true)?,
            (None, Some(t)) => (Vec3::from_array(*t.get_ref()) - camera.eye).dot(camera.axis()),
            (None, None) if radius > 0.0 => {
                let span = d.aperture_radius.as_ref().map_or(c.span(), |r| r.span());
                return self.fail(
                    span,
                    "camera.focus_distance",
                    "a lens needs focus_distance (the distance along the view to the plane in focus)",
                );
            }
            (None, None) => 0.0,
        };
        if radius > 0.0 {
            camera.projection = Projection::ThinLens { radius, focus };
        }
        Ok(camera)
    }

    pub(super) fn need_cam<'v, T>(
        &self,
        v: &'v Option<Spanned<T>>,
        c: &Spanned<CameraDef>,
        name: &str,
    ) -> Result<At<'v, T>, SceneError> {
        match v {
            Some(s) => Ok(at(s, format!("camera.{name}"))),
            None => self.fail(
                c.span(),
                &format!("camera.{name}"),
                format!("missing field `{name}` (give the four corners lower_left, lower_right, upper_left, upper_right, or target, up and vfov)"),
            ),
        }
    }
}

fn c_span(c: &Option<Spanned<V3>>, eye: &Spanned<V3>) -> Range<usize> {
    c.as_ref().map_or(eye.span(), |s| s.span())
}
