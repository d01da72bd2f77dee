//! Where the photons of light from everywhere (the constant sky, an
//! environment map) start: on the scene's box as the light sees it.
//!
//! Light arriving from infinity along a unit direction d falls on the
//! scene's box across its shadow, whose area is A(d) = Σ_k F_k |d_k| (F_k
//! the area of the faces across axis k). The shadow is tiled exactly by
//! the projections of the three faces d enters through, each of area
//! F_k |d_k|: a face drawn in proportion to that, and a point uniform on
//! it, is a point uniform on the shadow (a projection of a plane has a
//! constant Jacobian), density 1 / A(d). A photon starts a little
//! upstream of that point. A photon started on a disk round the box's
//! bounding sphere misses the box (and everything) wherever the disk is
//! not its shadow: for a flat scene seen edge-on, nearly everywhere. A
//! photon started on the shadow always enters the box; what it meets
//! inside is the scene's business.

use crate::math::{Color, Ray, Vertex};
use glam::{Vec2, Vec3};

/// The scene's box, as light from infinity reaches it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Reach {
    lo: Vec3,
    hi: Vec3,
}

impl Reach {
    pub fn new(lo: Vec3, hi: Vec3) -> Self {
        Reach { lo: lo.min(hi), hi: hi.max(lo) }
    }

    /// The areas of the box's faces across x, y and z.
    pub fn faces(&self) -> Vec3 {
        let e = self.hi - self.lo;
        Vec3::new(e.y * e.z, e.z * e.x, e.x * e.y)
    }

    /// The area of the box's shadow across unit `dir`.
    #[inline]
    pub fn area(&self, dir: Vec3) -> f32 {
        self.faces().dot(dir.abs())
    }

    /// How far upstream of the box a photon starts: past its diagonal,
    /// so that nothing of the scene lies behind it.
    fn margin(&self) -> f32 {
        (self.hi - self.lo).length().max(1e-3 * (self.lo.abs().max(self.hi.abs())).max_element()).max(1e-6)
    }

    /// A point upstream of the box for light travelling along unit `dir`:
    /// the plane through it, across `dir`, lies outside the box.
    pub fn upstream(&self, dir: Vec3) -> Vertex {
        0.5 * (self.lo + self.hi) - dir * self.margin()
    }

    /// Where a photon travelling along unit `dir` starts, for `u` uniform
    /// in the unit square: upstream of a point uniform on the box's
    /// shadow. `None` where the shadow is empty (a box of no extent
    /// across `dir`).
    #[inline]
    pub fn start(&self, dir: Vec3, u: Vec2) -> Option<Vertex> {
        let shares = self.faces() * dir.abs();
        let total = shares.x + shares.y + shares.z;
        if !(total > 0.0) {
            return None;
        }
        // The face: x, y or z by its share; u.x is stretched back to [0, 1).
        let pick = u.x * total;
        let (k, rest) = if pick < shares.x {
            (0, pick / shares.x)
        } else if pick < shares.x + shares.y {
            (1, (pick - shares.x) / shares.y)
        } else {
            (2, ((pick - shares.x - shares.y) / shares.z).min(1.0))
        };
        // The face d enters through: at lo where d runs up the axis.
        let mut p = Vec3::ZERO;
        p[k] = if dir[k] > 0.0 { self.lo[k] } else { self.hi[k] };
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        p[a] = self.lo[a] + rest.clamp(0.0, 1.0) * (self.hi[a] - self.lo[a]);
        p[b] = self.lo[b] + u.y * (self.hi[b] - self.lo[b]);
        Some(p - dir * self.margin())
    }

    /// The density per area (across its direction) with which
    /// [`Self::start`] gives the ray's origin: 1 / A where the ray enters
    /// the box, else zero.
    pub fn pdf(&self, ray: &Ray) -> f32 {
        let (mut t0, mut t1) = (0.0f32, f32::INFINITY);
        for k in 0..3 {
            let inv = 1.0 / ray.dir[k];
            let (a, b) = ((self.lo[k] - ray.origin[k]) * inv, (self.hi[k] - ray.origin[k]) * inv);
            let (near, far) = if a <= b { (a, b) } else { (b, a) };
            if near.is_nan() || far.is_nan() {
                if ray.origin[k] < self.lo[k] || ray.origin[k] > self.hi[k] {
                    return 0.0;
                }
                continue;
            }
            t0 = t0.max(near);
            t1 = t1.min(far);
        }
        let area = self.area(ray.dir);
        if t0 <= t1 * (1.0 + 1e-5) && area > 0.0 {
            1.0 / area
        } else {
            0.0
        }
    }

    /// The power light of ∫ L(ω) |ω_k| dω = `moments[k]` sends into the
    /// box: Σ_k F_k moments[k].
    pub fn power(&self, moments: [Color; 3]) -> Color {
        let f = self.faces();
        moments[0] * f.x + moments[1] * f.y + moments[2] * f.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Starts cover the shadow uniformly: binned on a grid across the
    /// direction, every cell the shadow covers fully holds its share; each
    /// start's ray enters the box; the shadow's area is the box's
    /// projection, measured by counting.
    #[test]
    fn starts_are_uniform_on_the_boxs_shadow() {
        let reach = Reach::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(2.0, 0.5, 3.0));
        let dir = Vec3::new(0.3, -0.5, 0.8).normalize();
        let frame = crate::math::Frame::from_normal(dir);
        let n = 400_000;
        let (cells, size) = (40usize, 5.0f32);
        let mut grid = vec![0u32; cells * cells];
        let mut rng = crate::sampling::stream(1, crate::sampling::Domain::Camera, 0);
        for _ in 0..n {
            let o = reach.start(dir, crate::sampling::next_2d(&mut rng)).unwrap();
            let ray = Ray::new(o, dir);
            assert!(reach.pdf(&ray) > 0.0, "{o} misses the box");
            let q = o - reach.upstream(dir);
            let (x, y) = (q.dot(frame.s), q.dot(frame.t));
            let (i, j) = (((x / size + 0.5) * cells as f32) as usize, ((y / size + 0.5) * cells as f32) as usize);
            grid[j.min(cells - 1) * cells + i.min(cells - 1)] += 1;
        }
        let cell_area = (size / cells as f32).powi(2);
        let per_full = n as f32 * cell_area / reach.area(dir);
        let full: Vec<u32> = grid.iter().copied().filter(|&c| c as f32 > 0.9 * per_full).collect();
        let mean = full.iter().sum::<u32>() as f32 / full.len() as f32;
        assert!((mean - per_full).abs() < 0.01 * per_full, "{mean} vs {per_full}");
        // The cells touched cover the shadow's area (within the cells cut by its rim).
        let touched = grid.iter().filter(|&&c| c > 0).count() as f32 * cell_area;
        assert!(touched >= reach.area(dir) && touched < 1.3 * reach.area(dir), "{touched} vs {}", reach.area(dir));
        // A ray beside the box has no density.
        assert_eq!(reach.pdf(&Ray::new(Vec3::new(5.0, 5.0, 5.0), dir)), 0.0);
    }

    /// A flat box (a floor) seen along its plane has no shadow; seen from
    /// above, its whole area.
    #[test]
    fn a_flat_box_casts_its_floor() {
        let reach = Reach::new(Vec3::new(-2.0, -2.0, 0.0), Vec3::new(2.0, 2.0, 0.0));
        assert_eq!(reach.start(Vec3::X, Vec2::splat(0.5)), None);
        assert_eq!(reach.area(-Vec3::Z), 16.0);
        let o = reach.start(-Vec3::Z, Vec2::new(0.25, 0.75)).unwrap();
        assert!(o.z > 0.0 && o.x.abs() <= 2.0 && o.y.abs() <= 2.0, "{o}");
    }
}
