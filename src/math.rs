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
#[derive(Clone, Copy, Debug, PartialEq)]
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

    /// The frame is orthonormal to rounding, so a unit `v` maps to a unit
    /// vector within a few ulps (tested below): callers mapping a unit sample
    /// need not normalise it.
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
#[inline]
pub fn offset_ray_origin(p: Vertex, p_err: Vec3, n: Vec3, dir: Direction) -> Vertex {
    let d = n.abs().dot(p_err);
    let mut offset = d * n;
    if dir.dot(n) < 0.0 {
        offset = -offset;
    }
    let po = p + offset;
    Vec3::new(nudge(po.x, offset.x), nudge(po.y, offset.y), nudge(po.z, offset.z))
}

/// `x.next_up()` where `towards > 0`, `x.next_down()` where `towards < 0`,
/// else `x`, for finite `x`, without branches: the offset's signs are
/// random from ray to ray, and the library functions' branches were
/// mispredicted often enough to cost 7% of the photon pass.
#[inline]
fn nudge(x: f32, towards: f32) -> f32 {
    let bits = x.to_bits();
    let up = (towards > 0.0) as u32;
    let moves = 0u32.wrapping_sub(up | (towards < 0.0) as u32);
    // A step up from a positive number, or down from a negative one, grows
    // the magnitude: one more in the bits; otherwise one less. Zero steps
    // to the smallest subnormal of the step's sign. Selected with masks:
    // written as branches, the compiler kept them.
    let grows = up ^ (bits >> 31);
    let stepped = bits.wrapping_add((grows << 1).wrapping_sub(1));
    let zero = 0u32.wrapping_sub((bits & 0x7FFF_FFFF == 0) as u32);
    let from_zero = 1 | ((1 - up) << 31);
    let next = (stepped & !zero) | (from_zero & zero);
    f32::from_bits((next & moves) | (bits & !moves))
}

/// A unit vector in 32 bits: its octahedral map (Meyer et al. 2010), two
/// 16-bit coordinates; decoded within 1e-4 of the direction (tested). For
/// the vertex normals of large meshes (12 bytes a triangle, not 36).
pub fn encode_unit(n: Vec3) -> u32 {
    let n = n / (n.x.abs() + n.y.abs() + n.z.abs());
    let (mut x, mut y) = (n.x, n.y);
    if n.z < 0.0 {
        (x, y) = ((1.0 - n.y.abs()) * n.x.signum(), (1.0 - n.x.abs()) * n.y.signum());
    }
    let q = |v: f32| (((v.clamp(-1.0, 1.0) * 0.5 + 0.5) * 65535.0).round() as u32) & 0xFFFF;
    q(x) | (q(y) << 16)
}

/// The unit vector [`encode_unit`] wrote.
pub fn decode_unit(bits: u32) -> Vec3 {
    let d = |v: u32| (v & 0xFFFF) as f32 / 65535.0 * 2.0 - 1.0;
    let (x, y) = (d(bits), d(bits >> 16));
    let z = 1.0 - x.abs() - y.abs();
    let t = (-z).max(0.0);
    let n = Vec3::new(x - t.copysign(x), y - t.copysign(y), z);
    n.normalize()
}

/// Largest component, used for Russian roulette on RGB weights.
pub fn max_component(c: Color) -> f32 {
    c.x.max(c.y).max(c.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The photon pass sends diffuse bounces along a cosine sample mapped
    /// through the frame without normalising it: the frame must be
    /// orthonormal to rounding for every normal, poles and grazing ones
    /// included (a frame off by 1e-3 would bend every diffuse photon).
    #[test]
    fn frames_map_unit_samples_to_unit_directions() {
        use crate::sampling::{cosine_hemisphere, next_2d, stream, uniform_cone, Domain};
        let mut rng = stream(3, Domain::Camera, 7);
        let mut normals: Vec<Vec3> = (0..100_000).map(|_| uniform_cone(next_2d(&mut rng), -1.0).normalize()).collect();
        normals.extend([Vec3::Z, -Vec3::Z, Vec3::X, -Vec3::Y, Vec3::new(1e-7, 0.0, -1.0).normalize()]);
        normals.extend([Vec3::new(0.6, 0.8, -0.0), Vec3::new(-0.6, 0.0, 1e-30).normalize()]);
        let mut worst = 0.0f32;
        for n in normals {
            let frame = Frame::from_normal(n);
            for _ in 0..4 {
                let d = frame.to_world(cosine_hemisphere(next_2d(&mut rng)));
                worst = worst.max((d.length() - 1.0).abs());
                assert!(d.dot(n) >= -1e-6, "{n} {d}");
            }
        }
        assert!(worst < 1e-6, "worst |length - 1| = {worst:e}");
    }

    #[test]
    fn unit_vectors_survive_their_32_bit_code() {
        use crate::sampling::{next_2d, stream, uniform_cone, Domain};
        let mut rng = stream(5, Domain::Camera, 1);
        let mut worst = 0.0f32;
        let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z, Vec3::new(1.0, -1.0, -1.0).normalize()];
        for n in axes.into_iter().chain((0..200_000).map(|_| uniform_cone(next_2d(&mut rng), -1.0).normalize())) {
            let back = decode_unit(encode_unit(n));
            worst = worst.max((back - n).length());
            assert!((back.length() - 1.0).abs() < 1e-6);
        }
        assert!(worst < 1e-4, "worst error {worst:e}");
    }

    #[test]
    fn nudge_steps_like_next_up_and_next_down() {
        let mut xs = vec![0.0f32, -0.0, 1.0, -1.0, f32::MIN_POSITIVE, -f32::MIN_POSITIVE, f32::MAX, f32::MIN];
        xs.extend([f32::from_bits(1), f32::from_bits(0x8000_0001), 1e-40, -1e-40, 3.0, -2.5e7]);
        // Finite floats of every exponent, from a fixed sequence of bits.
        let mut bits = 0x1234_5678u32;
        for _ in 0..200_000 {
            bits = bits.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let x = f32::from_bits(bits);
            if x.is_finite() {
                xs.push(x);
            }
        }
        for x in xs {
            for (towards, want) in [(1.0, x.next_up()), (-1.0, x.next_down()), (0.0, x), (-0.0, x), (f32::NAN, x)] {
                assert_eq!(nudge(x, towards).to_bits(), want.to_bits(), "{x:e} towards {towards}");
            }
        }
    }
}
