//! Textures: colours and numbers that vary over a surface, as Mitsuba 3
//! defines them (src/textures/*.cpp): an image ([`Bitmap`]), a checkerboard,
//! and a mesh's own per-vertex or per-face attribute. A texture is read at
//! a [`SurfacePoint`]: the surface's texture coordinates there
//! ([`SurfaceUv`]) and, for attributes, the primitive and its barycentrics.
//!
//! A scene without textures holds none of this: its materials are plain
//! [`crate::material::Material`]s and no hit computes a coordinate.

pub mod bitmap;
mod shading;
mod surface;

pub use bitmap::{Bitmap, Filter, Wrap};
pub use shading::{tangent_of, tangents, Perturb};
pub use surface::SurfaceUv;

use crate::math::Color;
use glam::{Affine2, Vec2};
use std::sync::Arc;

/// Where a texture is read.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    /// Texture coordinates, before a texture's own `to_uv`.
    pub uv: Vec2,
    pub prim: u32,
    /// The barycentric weights of a triangle's second and third corners.
    pub bary: Vec2,
}

#[derive(Clone, Debug)]
pub enum Texture {
    /// One value everywhere (Mitsuba's `rawconstant`).
    Constant(Color),
    Bitmap {
        image: Arc<Bitmap>,
        to_uv: Affine2,
    },
    /// Squares of `color0` and `color1`, two by two per unit of uv.
    Checkerboard {
        color0: Color,
        color1: Color,
        to_uv: Affine2,
    },
    /// A mesh attribute: per primitive, its value at the three corners (a
    /// face attribute's three are equal), zero for primitives without it;
    /// interpolated with the barycentrics.
    Attribute {
        values: Arc<Vec<[Color; 3]>>,
        scale: f32,
    },
}

impl Texture {
    /// The colour at `at`.
    pub fn eval(&self, at: &SurfacePoint) -> Color {
        match self {
            Texture::Constant(c) => *c,
            Texture::Bitmap { image, to_uv } => image.eval(to_uv.transform_point2(at.uv)),
            Texture::Checkerboard { color0, color1, to_uv } => {
                if checker(to_uv.transform_point2(at.uv)) {
                    *color0
                } else {
                    *color1
                }
            }
            Texture::Attribute { values, scale } => match values.get(at.prim as usize) {
                Some(v) => (v[0] * (1.0 - at.bary.x - at.bary.y) + v[1] * at.bary.x + v[2] * at.bary.y) * *scale,
                None => Color::ZERO,
            },
        }
    }

    /// A single number at `at`, as Mitsuba's `eval_1` gives it: a colour
    /// image's luminance, a checkerboard's squares the other way round
    /// (checkerboard.cpp does so), an attribute's first component.
    pub fn eval_1(&self, at: &SurfacePoint) -> f32 {
        match self {
            Texture::Bitmap { image, .. } if !image.is_grey() => luminance(self.eval(at)),
            Texture::Checkerboard { color0, color1, to_uv } => {
                if checker(to_uv.transform_point2(at.uv)) {
                    color1.x
                } else {
                    color0.x
                }
            }
            _ => self.eval(at).x,
        }
    }

    /// The gradient of [`Self::eval_1`] by the texture coordinates, as
    /// Mitsuba's `eval_1_grad` gives it: a bilinear image's exact
    /// derivative through its `to_uv` (zero for nearest lookup and the
    /// other textures, piecewise constant).
    pub fn eval_1_grad(&self, at: &SurfacePoint) -> Vec2 {
        match self {
            Texture::Bitmap { image, to_uv } => {
                let g = image.gradient(to_uv.transform_point2(at.uv));
                let m = to_uv.matrix2;
                // Mitsuba multiplies by the transform's transpose, then by the resolution.
                let df = Vec2::new(m.x_axis.x * g.x + m.x_axis.y * g.y, m.y_axis.x * g.x + m.y_axis.y * g.y);
                df * image.resolution()
            }
            _ => Vec2::ZERO,
        }
    }

    /// The texture's mean over its domain (a checkerboard's two colours
    /// equally, an image's texels, an attribute's primitives).
    pub fn mean(&self) -> Color {
        match self {
            Texture::Constant(c) => *c,
            Texture::Bitmap { image, .. } => image.mean(),
            Texture::Checkerboard { color0, color1, .. } => 0.5 * (*color0 + *color1),
            Texture::Attribute { values, scale } => {
                let n = values.len().max(1) as f32;
                values.iter().map(|v| (v[0] + v[1] + v[2]) / 3.0).sum::<Color>() / n * *scale
            }
        }
    }

    /// The largest value any channel takes.
    pub fn max(&self) -> f32 {
        match self {
            Texture::Constant(c) => c.max_element(),
            Texture::Bitmap { image, .. } => image.max(),
            Texture::Checkerboard { color0, color1, .. } => color0.max_element().max(color1.max_element()),
            Texture::Attribute { values, scale } => {
                values.iter().flatten().map(|c| c.max_element()).fold(0.0, f32::max) * scale
            }
        }
    }

    /// The smallest value any channel takes.
    pub fn min(&self) -> f32 {
        match self {
            Texture::Constant(c) => c.min_element(),
            Texture::Bitmap { image, .. } => image.min(),
            Texture::Checkerboard { color0, color1, .. } => color0.min_element().min(color1.min_element()),
            Texture::Attribute { values, scale } => {
                values.iter().flatten().map(|c| c.min_element() * scale).fold(0.0, f32::min)
            }
        }
    }
}

/// Whether `uv` lies in a `color0` square (checkerboard.cpp: the
/// fractional parts both above or both below one half).
fn checker(uv: Vec2) -> bool {
    let f = uv - uv.floor();
    (f.x > 0.5) == (f.y > 0.5)
}

/// A grey texel's value, or an RGB one's luminance.
#[inline]
pub fn luminance_or_grey(c: Color, grey: bool) -> f32 {
    if grey {
        c.x
    } else {
        luminance(c)
    }
}

/// Rec. 709 luminance of linear RGB.
pub fn luminance(c: Color) -> f32 {
    0.212_671 * c.x + 0.715_160 * c.y + 0.072_169 * c.z
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(u: f32, v: f32) -> SurfacePoint {
        SurfacePoint { uv: Vec2::new(u, v), prim: 0, bary: Vec2::ZERO }
    }

    #[test]
    fn a_checkerboard_alternates_by_half_units_of_uv() {
        let t = Texture::Checkerboard {
            color0: Color::splat(0.8),
            color1: Color::splat(0.1),
            to_uv: Affine2::from_scale(Vec2::splat(5.0)),
        };
        assert_eq!(t.eval(&at(0.05, 0.05)).x, 0.8);
        assert_eq!(t.eval(&at(0.15, 0.05)).x, 0.1);
        assert_eq!(t.eval(&at(0.15, 0.15)).x, 0.8);
        assert_eq!(t.eval_1(&at(0.05, 0.05)), 0.1);
        assert!((t.mean().x - 0.45).abs() < 1e-6);
    }

    #[test]
    fn attributes_interpolate_with_barycentrics() {
        let values = Arc::new(vec![[Color::X, Color::Y, Color::Z]]);
        let t = Texture::Attribute { values, scale: 2.0 };
        let p = SurfacePoint { uv: Vec2::ZERO, prim: 0, bary: Vec2::new(0.25, 0.5) };
        assert!((t.eval(&p) - Color::new(0.5, 0.5, 1.0)).length() < 1e-6);
        let outside = SurfacePoint { prim: 7, ..p };
        assert_eq!(t.eval(&outside), Color::ZERO);
    }
}
