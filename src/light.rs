//! Lights. The default scene has one: a one-sided Lambertian disk.
//! Each light can be sampled by area for shadow rays and can emit photons;
//! both use the same geometry so they agree on its power.

use crate::math::{Color, Frame, Ray, Vertex};
use crate::sampling::{concentric_disk, cosine_hemisphere};
use crate::shape::Disk;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A one-sided disk of constant radiance emitting along `disk.normal`.
#[derive(Clone, Copy, Debug)]
pub struct DiskLight {
    pub disk: Disk,
    pub radiance: Color,
    /// Index of the disk's primitive in the scene (shadow rays ignore it).
    pub prim: u32,
    frame: Frame,
}

/// A point on a light, chosen for a shadow ray.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub point: Vertex,
    pub normal: Vec3,
    /// pdf with respect to the light's area.
    pub pdf_area: f32,
}

impl DiskLight {
    pub fn new(disk: Disk, radiance: Color, prim: u32) -> Self {
        DiskLight { disk, radiance, prim, frame: Frame::from_normal(disk.normal) }
    }

    pub fn area(&self) -> f32 {
        self.disk.area()
    }

    /// Total emitted power per channel: pi * A * L for a Lambertian emitter.
    pub fn power(&self) -> Color {
        PI * self.area() * self.radiance
    }

    /// Radiance leaving the light towards `-dir` for a ray travelling along
    /// `dir`; zero from the back side.
    pub fn radiance_towards(&self, dir: Vec3) -> Color {
        if dir.dot(self.disk.normal) < 0.0 {
            self.radiance
        } else {
            Color::ZERO
        }
    }

    /// Uniform point on the disk (pdf 1 / area).
    pub fn sample_point(&self, u: Vec2) -> LightSample {
        let d = concentric_disk(u) * self.disk.radius;
        LightSample {
            point: self.disk.center + self.frame.s * d.x + self.frame.t * d.y,
            normal: self.disk.normal,
            pdf_area: 1.0 / self.area(),
        }
    }

    /// A photon's start: uniform position, cosine-distributed direction. With
    /// these pdfs every photon of N carries exactly power / N.
    pub fn emit(&self, u_pos: Vec2, u_dir: Vec2) -> Ray {
        let p = self.sample_point(u_pos).point;
        Ray::new(p, self.frame.to_world(cosine_hemisphere(u_dir)).normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Irradiance on the axis at height h below a Lambertian disk of radius r:
    /// E = pi L r^2 / (r^2 + h^2). Estimate it by area sampling.
    #[test]
    fn disk_irradiance_on_axis_matches_closed_form() {
        let light = DiskLight::new(
            Disk { center: Vec3::new(8.0, 0.0, 4.999), normal: -Vec3::Z, radius: 1.0 },
            Color::splat(10.0),
            0,
        );
        let mut rng = crate::sampling::stream(7, crate::sampling::Domain::Camera, 0);
        for h in [0.5f32, 2.0, 9.999] {
            let x = light.disk.center - h * Vec3::Z;
            let n = 200_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let s = light.sample_point(crate::sampling::next_2d(&mut rng));
                let d = s.point - x;
                let dist2 = d.length_squared();
                let w = d / dist2.sqrt();
                let cos_x = w.dot(Vec3::Z);
                let cos_l = (-w).dot(s.normal);
                sum += (10.0 * cos_x * cos_l / dist2 / s.pdf_area) as f64;
            }
            let est = sum / n as f64;
            let exact = (PI * 10.0 / (1.0 + h * h)) as f64;
            assert!((est - exact).abs() / exact < 0.01, "h={h}: {est} vs {exact}");
        }
        // The spec's check: floor radiance below the light, direct only.
        let h = 4.999f64 + 5.0;
        let floor = 0.8 / std::f64::consts::PI * std::f64::consts::PI * 10.0 / (1.0 + h * h);
        assert!((floor - 0.07922).abs() < 1e-4);
    }
}
