//! Surface materials: a closed set, spelled out.

use crate::math::{max_component, Color};

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Ideal diffuse reflector, BRDF = rho / pi, per channel.
    Lambertian { rho: Color },
    /// Perfect specular mirror.
    Mirror { reflectance: Color },
    /// Smooth dielectric: exact Fresnel, Snell refraction, total internal
    /// reflection. `ior` is the index inside (the side the normal points away from).
    Glass { ior: f32 },
    /// A light's own surface: it emits (through its light) and reflects nothing.
    Emitter,
}

impl Material {
    /// Mirror and glass: light leaving them is found by following rays, never
    /// by density estimation.
    pub fn is_specular(&self) -> bool {
        matches!(self, Material::Mirror { .. } | Material::Glass { .. })
    }

    /// A surface that stores photons and is shaded by the estimators; black
    /// diffuse surfaces reflect nothing and need no estimate.
    pub fn diffuse_rho(&self) -> Option<Color> {
        match self {
            Material::Lambertian { rho } if max_component(*rho) > 0.0 => Some(*rho),
            _ => None,
        }
    }
}
