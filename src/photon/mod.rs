//! Photons: the photon pass ([`trace`]) and the maps that store them ([`map`]).
//!
//! Two passes fill two maps (Jensen 1996):
//! * the **global pass** emits photons from the lights with their natural
//!   (cosine) distribution and stores every diffuse hit but a photon's
//!   first (light straight from a light, which shadow rays find exactly)
//!   in the global map; it is read only through the precomputed irradiance
//!   of final gathering, which adds the direct part;
//! * the **caustic pass** aims photons at the bounding spheres of mirror and
//!   glass objects (with their power corrected by the sampling pdf, so the
//!   estimate is unchanged) and stores only the paths light → specular+ →
//!   diffuse: the caustic map, read directly at visible surfaces.

pub mod aims;
mod blocks;
mod facing;
mod grid;
pub mod guide;
pub mod irradiance_cache;
mod kdtree;
pub mod map;
pub mod media_trace;
mod morton;
pub mod spots;
pub mod trace;
pub mod volume_grid;
pub mod volume_map;

pub use blocks::PhotonBlocks;

use crate::math::Color;
use glam::Vec3;

/// One stored photon: 28 bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Photon {
    pub pos: [f32; 3],
    /// Flux carried (per channel).
    pub power: [f32; 3],
    /// Surface normal at the hit, turned towards the side the photon arrived
    /// from, as three signed bytes (n * 127): estimates skip photons on
    /// other surfaces, a test that needs no precision but must be cheap.
    /// (No incoming direction: photons are stored and read only on
    /// Lambertian surfaces and lobes, whose estimate does not use it.)
    pub normal: [i8; 4],
}

impl Photon {
    pub fn new(pos: Vec3, power: Color, normal: Vec3) -> Self {
        debug_assert!(power.is_finite() && pos.is_finite(), "photon power {power} at {pos}");
        Photon { pos: pos.to_array(), power: power.to_array(), normal: quantize_normal(normal) }
    }

    pub fn position(&self) -> Vec3 {
        Vec3::from(self.pos)
    }

    pub fn flux(&self) -> Color {
        Vec3::from(self.power)
    }

    pub fn surface_normal(&self) -> Vec3 {
        normal_times_127(self.normal) / 127.0
    }
}

/// A unit normal in three signed bytes (angle error below 0.5 degrees).
pub fn quantize_normal(n: Vec3) -> [i8; 4] {
    let q = (n * 127.0).clamp(Vec3::splat(-127.0), Vec3::splat(127.0));
    [q.x.round() as i8, q.y.round() as i8, q.z.round() as i8, 0]
}

/// A [`quantize_normal`] code as the vector it stands for, times 127.
pub(crate) fn normal_times_127(q: [i8; 4]) -> Vec3 {
    Vec3::new(q[0] as f32, q[1] as f32, q[2] as f32)
}

/// A hint to the processor to bring `value`'s cache line in; nothing else.
#[inline(always)]
pub(crate) fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch has no effect on memory or registers; the address
    // is that of a live reference.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>((value as *const T).cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn photon_is_28_bytes() {
        assert_eq!(std::mem::size_of::<Photon>(), 28);
    }
}
