//! A scene's textures and where they are read: the shading frame a
//! texture coordinate and a normal or bump map give a hit, and the
//! material a blend shows.

use super::Hit;
use crate::shape::Shape;
use glam::Vec3;

/// A scene's textures ([`crate::texture`]): the textures, the materials
/// that read them, and where on each primitive they are read.
#[derive(Clone, Debug, Default)]
pub struct Texturing {
    pub textures: Vec<crate::texture::Texture>,
    /// Per material: its recipe where it is textured (as long as the
    /// materials, or shorter: the rest are plain).
    pub materials: Vec<Option<crate::material::Textured>>,
    /// Per primitive: its texture coordinates (as long as the primitives,
    /// or shorter: the rest use their barycentrics).
    pub surfaces: Vec<crate::texture::SurfaceUv>,
    /// The analytic shapes' world-to-object transforms that `surfaces` name.
    pub frames: Vec<glam::Affine3A>,
    /// Per material: the normal or bump map it is seen through, if any.
    pub perturb: Vec<Option<crate::texture::Perturb>>,
    /// Per light of the scene's parts: an image over a triangle light.
    pub light_patterns: Vec<Option<std::sync::Arc<crate::light::AreaPattern>>>,
}

impl Texturing {
    /// Whether any material reads a texture.
    pub fn is_used(&self) -> bool {
        self.materials.iter().any(Option::is_some) || self.perturb.iter().any(Option::is_some)
    }

    /// Gives `hit` its shading frame from the texture coordinates, bent by
    /// the material's normal or bump map.
    #[inline(never)]
    pub(super) fn shade(&self, hit: &mut Hit, shape: &Shape, material: u32) {
        let Some(surface) = self.surfaces.get(hit.prim as usize) else { return };
        let tangents = crate::texture::tangents(surface, shape, hit.point, &self.frames);
        hit.tangent = crate::texture::tangent_of(hit.shading_normal, tangents.0);
        if let Some(Some(p)) = self.perturb.get(material as usize) {
            let at = self.point(hit);
            if let Some((n, s)) = p.apply(&at, &self.textures, hit.shading_normal, hit.normal, tangents) {
                if n.dot(hit.normal) > 0.0 {
                    (hit.shading_normal, hit.tangent) = (n, s);
                }
            }
        }
    }

    /// Material `m`, or where it is a blend, the material of it that `hit`
    /// shows a ray travelling along `dir` (nests of blends followed down).
    #[inline]
    pub(super) fn pick(&self, hit: &Hit, dir: Vec3, mut m: usize) -> usize {
        let mut depth = 0;
        // The front-ends make no cycle; the bound keeps a malformed one finite.
        while let Some(Some(crate::material::Textured::Blend { weight, first, second })) = self.materials.get(m) {
            if depth == 64 {
                break;
            }
            let w = match weight {
                crate::material::Param::Fixed(c) => c.x,
                p => p.number(&self.point(hit), &self.textures),
            };
            let mix = crate::material::hit_random(hit.point, dir, depth);
            m = if mix < w { *second } else { *first } as usize;
            depth += 1;
        }
        m
    }

    /// Where textures are read at `hit`.
    #[inline]
    pub fn point(&self, hit: &Hit) -> crate::texture::SurfacePoint {
        let surface = self.surfaces.get(hit.prim as usize).copied().unwrap_or(crate::texture::SurfaceUv::Barycentric);
        crate::texture::SurfacePoint {
            uv: surface.uv(hit.point, hit.bary, &self.frames),
            prim: hit.prim,
            bary: hit.bary,
        }
    }
}
