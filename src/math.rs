//! The course's vocabulary over glam: `Vertex`, `Direction` and `Color` are
//! `Vec3`s; a [`Ray`] is an origin and a unit direction; a [`Frame`] is the
//! local coordinate system of a surface, with the normal as its z axis, in
//! which reflection and refraction are computed (TNCG15 lecture 6).
//!
//! Ray origins leaving a surface are moved off it by [`offset_ray_origin`],
//! by a bound derived from the floating-point error of the hit point, not by
//! a constant tuned to one scene's size.

use glam::Vec3;

/// A point in space (the course's `Vertex`).
pub type Vertex = Vec3;
/// A direction, unit length unless stated otherwise (the course's `Direction`).
pub type Direction = Vec3;
/// Linear RGB radiance, power or reflectance (the course's `ColorDbl`).
pub type Color = Vec3;

/// A half-line `origin + t * dir`, `t > 0`; `dir` is unit length.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vertex,
    pub dir: Direction,
}

impl Ray {
    pub fn new(origin: Vertex, dir: Direction) -> Self {
        debug_assert!(dir.is_finite() && (dir.length() - 1.0).abs() < 1e-3, "ray dir {dir}");
        Ray { origin, dir }
    }

    pub fn at(&self, t: f32) -> Vertex {
        self.origin + t * self.dir
    }
}

/// An orthonormal frame `(s, t, n)`: local z is the normal.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// Builds a frame around a unit normal (Duff et al. 2017, branchless and
    /// continuous except at n.z = -0 / +0, where either choice is valid).
    pub fn from_normal(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }

    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

/// Bound on the relative rounding error of `n` chained f32 operations
/// (Higham's gamma_n, as in pbrt).
pub const fn gamma(n: i32) -> f32 {
    let e = f32::EPSILON * 0.5;
    (n as f32 * e) / (1.0 - n as f32 * e)
}

/// Moves a hit point `p`, whose coordinates are known to within `p_err`, off
/// the surface with geometric normal `n`, to the side `dir` leaves towards.
/// The offset is the error box projected on the normal, then rounded one ulp
/// further, so the new origin is provably on the correct side of the surface
/// whatever the scene's scale.
pub fn offset_ray_origin(p: Vertex, p_err: Vec3, n: Vec3, dir: Direction) -> Vertex {
    let d = n.abs().dot(p_err);
    let mut offset = d * n;
    if dir.dot(n) < 0.0 {
        offset = -offset;
    }
    let mut po = p + offset;
    for i in 0..3 {
        if offset[i] > 0.0 {
            po[i] = po[i].next_up();
        } else if offset[i] < 0.0 {
            po[i] = po[i].next_down();
        }
    }
    po
}

/// Largest component, used for Russian roulette on RGB weights.
pub fn max_component(c: Color) -> f32 {
    c.x.max(c.y).max(c.z)
}
