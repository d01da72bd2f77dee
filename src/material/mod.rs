//! Surface materials: a closed set, each answering for itself in the local
//! frame of the surface (TNCG15's local coordinate systems): the normal is
//! +z on the side the ray or photon arrives from, `wo` points back along
//! it (so `wo.z > 0`), and `entering` says whether that side is the front
//! of the geometric normal (for glass: whether light enters the body).
//!
//! A material has up to three kinds of lobe, each owned by one estimator of
//! photon mapping (notes/method.md):
//! * **diffuse** (Lambertian): where photons are stored and density
//!   estimates read ([`Material::diffuse_rho`]);
//! * **glossy** (Phong's lobe): sampled like a path tracer;
//! * **specular** (mirror, glass, Phong's mirror): perfect reflection and
//!   refraction, followed by rays ([`Material::specular_branches`]).
//!
//! [`Material::eval`] and [`Material::pdf`] cover the smooth lobes (diffuse
//! and glossy); [`Material::sample`] picks any lobe. Adding a material is a
//! variant here and its answers to these questions, and its fields in the
//! scene file (notes/architecture.md).

mod phong;

pub use phong::Phong;

use crate::math::{max_component, Color};
use crate::optics::{fresnel_dielectric, reflect, refract};
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf, next_2d, Rng};
use glam::Vec3;
use rand::RngExt;
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Ideal diffuse reflector, BRDF = rho / pi, per channel.
    Lambertian { rho: Color },
    /// Perfect specular mirror.
    Mirror { reflectance: Color },
    /// Smooth dielectric: exact Fresnel, Snell refraction, total internal
    /// reflection. `ior` is the index inside (the side the normal points
    /// away from); light travelling inside loses exp(-absorption * distance)
    /// per channel (Beer–Lambert).
    Glass { ior: f32, absorption: Color },
    /// The Whitted course's material (see [`Phong`]).
    Phong(Phong),
    /// A light's own surface: it emits (through its light) and reflects nothing.
    Emitter,
}

/// Which way a path carries light, where it matters: a camera path
/// (radiance) crossing into glass is scaled by (n_i / n_t)^2, a photon
/// (importance, carrying power) is not (Veach 1997, ch. 5).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    Radiance,
    Importance,
}

/// The kind of lobe a scattered direction came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lobe {
    Diffuse,
    Glossy,
    Specular,
}

/// A direction a material scattered into.
#[derive(Clone, Copy, Debug)]
pub struct Scatter {
    /// Local, unit length (to rounding; specular directions are mapped to
    /// world space and normalised by the caller, see [`Lobe`]).
    pub wi: Vec3,
    /// What the path's weight is multiplied by: f |cos| / pdf, the chance
    /// of the lobe's choice included; for a specular branch its scale.
    pub weight: Color,
    pub lobe: Lobe,
}

/// One perfect reflection or refraction leaving a surface.
#[derive(Clone, Copy, Debug)]
pub struct Branch {
    /// Local direction (unit to rounding).
    pub wi: Vec3,
    /// The share of the light this branch takes (Fresnel's for glass, 1 for
    /// a mirror), and the chance it is chosen when only one is followed.
    pub prob: f32,
    /// What light along the branch is multiplied by besides `prob`: a
    /// mirror's reflectance, refraction's radiance scale.
    pub scale: Color,
}

/// A material's specular branches: none, one (a mirror, total internal
/// reflection), or two (glass: reflection and refraction).
#[derive(Clone, Copy, Debug, Default)]
pub struct Branches {
    items: [Option<Branch>; 2],
}

impl Branches {
    fn one(b: Branch) -> Self {
        Branches { items: [Some(b), None] }
    }

    pub fn iter(&self) -> impl Iterator<Item = &Branch> {
        self.items.iter().flatten()
    }

    pub fn is_empty(&self) -> bool {
        self.items[0].is_none()
    }

    /// One branch chosen with its probability; a lone branch is taken
    /// without drawing (a mirror costs no random number).
    pub fn choose(&self, rng: &mut Rng) -> Option<Branch> {
        match self.items {
            [Some(a), Some(b)] => Some(if rng.random::<f32>() < a.prob { a } else { b }),
            [a, _] => a,
        }
    }
}

impl Material {
    /// Clear glass of index `ior`.
    pub fn glass(ior: f32) -> Self {
        Material::Glass { ior, absorption: Color::ZERO }
    }

    pub fn is_emitter(&self) -> bool {
        matches!(self, Material::Emitter)
    }

    /// Mirror and glass: all light leaving them is found by following rays,
    /// never by density estimation.
    pub fn is_specular(&self) -> bool {
        matches!(self, Material::Mirror { .. } | Material::Glass { .. })
    }

    /// Whether light can leave the surface by a perfect mirror or refraction
    /// (photons aimed at it may make caustics).
    pub fn has_specular_lobe(&self) -> bool {
        match self {
            Material::Phong(p) => max_component(p.mirror_rho()) > 0.0,
            m => m.is_specular(),
        }
    }

    /// The diffuse lobe's reflectance: where photons are stored and density
    /// estimates read. `None` where there is none, or it is black (a black
    /// surface reflects nothing and needs no estimate).
    pub fn diffuse_rho(&self) -> Option<Color> {
        let rho = match self {
            Material::Lambertian { rho } => *rho,
            Material::Phong(p) => p.diffuse_rho(),
            _ => return None,
        };
        (max_component(rho) > 0.0).then_some(rho)
    }

    /// The glossy lobe, if the material has one that reflects.
    pub fn glossy(&self) -> Option<&Phong> {
        match self {
            Material::Phong(p) if p.is_glossy() => Some(p),
            _ => None,
        }
    }

    /// What light travelling inside loses per unit length (Beer–Lambert),
    /// where that is anything.
    pub fn absorption(&self) -> Option<Color> {
        match *self {
            Material::Glass { absorption, .. } if absorption != Color::ZERO => Some(absorption),
            _ => None,
        }
    }

    /// The chance a photon goes on from this surface (Russian roulette):
    /// the largest fraction of power the smooth lobes and Phong's mirror
    /// reflect (Jensen 2001, ch. 5); 1 for mirrors and glass, whose photons
    /// are never dropped (their chains make the caustics).
    pub fn photon_survival(&self) -> f32 {
        match self {
            Material::Lambertian { rho } => max_component(*rho).min(1.0),
            Material::Phong(p) => p.lobe_weights().iter().sum::<f32>().min(1.0),
            Material::Mirror { .. } | Material::Glass { .. } => 1.0,
            Material::Emitter => 0.0,
        }
    }

    /// How the Whitted course's formula reads the material (the `trace`
    /// program): Phong as itself, a Lambertian rho as C = rho, m_l = 1 / pi,
    /// m_a = 1 (its direct light is then photonmap's); `None` where only
    /// its specular branches (mirrors, glass) or nothing (lights) reflect.
    pub fn course_phong(&self) -> Option<Phong> {
        match *self {
            Material::Phong(p) => Some(p),
            Material::Lambertian { rho } => Some(Phong {
                color: rho,
                ambient: 1.0,
                diffuse: 1.0 / PI,
                specular: 0.0,
                metalness: 0.0,
                shininess: 1.0,
                mirror: 0.0,
            }),
            _ => None,
        }
    }

    /// The smooth part of the BSDF, f(wo, wi), for local directions on the
    /// surface's side (zero below it); specular lobes are not included.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Color {
        if !(wi.z > 0.0) {
            return Color::ZERO;
        }
        match self {
            Material::Lambertian { rho } => *rho / PI,
            Material::Phong(p) => p.diffuse_rho() / PI + p.glossy(wo, wi),
            _ => Color::ZERO,
        }
    }

    /// The density (per solid angle) with which [`Self::sample`] returns
    /// `wi` through a smooth lobe.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Material::Lambertian { .. } => cosine_hemisphere_pdf(wi),
            Material::Phong(p) => {
                let [d, g, m] = p.lobe_weights();
                let total = d + g + m;
                if !(total > 0.0) {
                    return 0.0;
                }
                (d * cosine_hemisphere_pdf(wi) + g * p.glossy_pdf(wo, wi)) / total
            }
            _ => 0.0,
        }
    }

    /// The perfect reflections and refractions leaving the surface towards
    /// `wo`'s side or through it. Glass: reflection with Fresnel's share
    /// and refraction with the rest (scaled by (n_i / n_t)^2 for radiance),
    /// or reflection alone past the critical angle.
    #[inline]
    pub fn specular_branches(&self, wo: Vec3, entering: bool, mode: Transport) -> Branches {
        match *self {
            Material::Mirror { reflectance } if max_component(reflectance) > 0.0 => {
                Branches::one(Branch { wi: reflect(wo), prob: 1.0, scale: reflectance })
            }
            Material::Phong(p) if max_component(p.mirror_rho()) > 0.0 => {
                Branches::one(Branch { wi: reflect(wo), prob: 1.0, scale: p.mirror_rho() })
            }
            Material::Glass { ior, .. } => {
                let (n_i, n_t) = if entering { (1.0, ior) } else { (ior, 1.0) };
                let reflected = |prob| Branch { wi: reflect(wo), prob, scale: Color::ONE };
                match refract(wo, n_i / n_t) {
                    None => Branches::one(reflected(1.0)),
                    Some(wt) => {
                        let r = fresnel_dielectric(wo.z, n_i, n_t);
                        let scale = match mode {
                            Transport::Radiance => Color::splat((n_i / n_t).powi(2)),
                            Transport::Importance => Color::ONE,
                        };
                        Branches { items: [Some(reflected(r)), Some(Branch { wi: wt, prob: 1.0 - r, scale })] }
                    }
                }
            }
            _ => Branches::default(),
        }
    }

    /// A scattered direction from one of the material's lobes, chosen in
    /// proportion to what each reflects (Phong: the largest channel of each
    /// lobe's albedo; glass: Fresnel's shares). The weight is f |cos| /
    /// pdf over the smooth lobes ([`Self::eval`], [`Self::pdf`]), or a
    /// specular branch's scale over the chance of its lobe. `None` for a
    /// surface that reflects nothing, or a glossy sample below the surface.
    pub fn sample(&self, wo: Vec3, entering: bool, mode: Transport, rng: &mut Rng) -> Option<Scatter> {
        let specular = |b: Branch| Scatter { wi: b.wi, weight: b.scale, lobe: Lobe::Specular };
        match self {
            Material::Lambertian { rho } => {
                // Cosine sampling: f cos / pdf = (rho / pi) cos / (cos / pi) = rho.
                Some(Scatter { wi: cosine_hemisphere(next_2d(rng)), weight: *rho, lobe: Lobe::Diffuse })
            }
            Material::Mirror { .. } | Material::Glass { .. } => {
                self.specular_branches(wo, entering, mode).choose(rng).map(specular)
            }
            Material::Phong(p) => {
                let w = p.lobe_weights();
                let total: f32 = w.iter().sum();
                if !(total > 0.0) {
                    return None;
                }
                let u = rng.random::<f32>() * total;
                if u < w[0] + w[1] {
                    // A smooth lobe's direction is weighed by the smooth
                    // lobes' mixture (f cos / pdf with the pdf of both), so
                    // that neither lobe's samples miss the other's light.
                    let (wi, lobe) = if u < w[0] {
                        (cosine_hemisphere(next_2d(rng)), Lobe::Diffuse)
                    } else {
                        (p.sample_glossy(wo, next_2d(rng))?.0, Lobe::Glossy)
                    };
                    let pdf = self.pdf(wo, wi);
                    (pdf > 0.0).then(|| Scatter { wi, weight: self.eval(wo, wi) * (wi.z / pdf), lobe })
                } else {
                    let b = self.specular_branches(wo, entering, mode).choose(rng)?;
                    Some(Scatter { weight: b.scale * (total / w[2]), ..specular(b) })
                }
            }
            Material::Emitter => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{stream, uniform_cone, Domain};

    fn phong() -> Phong {
        Phong {
            color: Color::new(0.9, 0.6, 0.3),
            ambient: 0.0,
            diffuse: 0.4,
            specular: 0.3,
            metalness: 0.2,
            shininess: 20.0,
            mirror: 0.2,
        }
    }

    fn materials() -> Vec<Material> {
        vec![
            Material::Lambertian { rho: Color::new(0.8, 0.5, 0.2) },
            Material::Mirror { reflectance: Color::splat(0.95) },
            Material::glass(1.5),
            Material::Phong(phong()),
        ]
    }

    /// For every material, the mean weight of its samples is the fraction
    /// of light it reflects towards `wo` (a white furnace per direction):
    /// the smooth lobes' integral of f cos, estimated independently with
    /// uniform directions, plus the specular branches' shares.
    #[test]
    fn sample_weights_average_to_the_reflected_fraction() {
        let mut rng = stream(2, Domain::Camera, 0);
        for m in materials() {
            for wo in [Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, -0.95, 0.3122499).normalize()] {
                let n = 400_000;
                let mut sampled = Color::ZERO.as_dvec3();
                for _ in 0..n {
                    if let Some(s) = m.sample(wo, true, Transport::Importance, &mut rng) {
                        sampled += s.weight.as_dvec3();
                    }
                }
                let mut smooth = Color::ZERO.as_dvec3();
                for _ in 0..n {
                    let wi = uniform_cone(next_2d(&mut rng), 0.0);
                    smooth += (m.eval(wo, wi) * wi.z * 2.0 * PI).as_dvec3();
                }
                let specular: Color =
                    m.specular_branches(wo, true, Transport::Importance).iter().map(|b| b.prob * b.scale).sum();
                let want = smooth / n as f64 + specular.as_dvec3();
                let got = sampled / n as f64;
                for c in 0..3 {
                    assert!((got[c] - want[c]).abs() < 0.01 + 0.01 * want[c], "{m:?} wo {wo}: {got} vs {want}");
                }
            }
        }
    }

    /// Where a sample came from a smooth lobe, its weight is f cos / pdf
    /// by the material's own eval and pdf (sampler and pdf agree).
    #[test]
    fn smooth_samples_weigh_f_cos_over_pdf() {
        let mut rng = stream(3, Domain::Camera, 0);
        let wo = Vec3::new(0.3, 0.4, 0.866).normalize();
        for m in [Material::Lambertian { rho: Color::splat(0.7) }, Material::Phong(Phong { mirror: 0.0, ..phong() })] {
            let mut checked = 0;
            for _ in 0..20_000 {
                let Some(s) = m.sample(wo, true, Transport::Radiance, &mut rng) else { continue };
                if s.lobe == Lobe::Specular {
                    continue;
                }
                let want = m.eval(wo, s.wi) * s.wi.z / m.pdf(wo, s.wi);
                assert!((s.weight - want).abs().max_element() <= 1e-3 * want.max_element(), "{s:?} vs {want}");
                checked += 1;
            }
            assert!(checked > 10_000);
        }
    }

    /// Glass: the shares add to one, refraction follows Snell, a camera
    /// path crossing in is scaled by (1 / 1.5)^2 and a photon is not; past
    /// the critical angle from inside, reflection alone.
    #[test]
    fn glass_branches_share_the_light() {
        let glass = Material::glass(1.5);
        let wo = Vec3::new(0.5, 0.0, 0.75f32.sqrt());
        let b: Vec<Branch> = glass.specular_branches(wo, true, Transport::Radiance).iter().copied().collect();
        assert_eq!(b.len(), 2);
        assert!((b[0].prob + b[1].prob - 1.0).abs() < 1e-6);
        assert!(b[1].wi.z < 0.0 && (0.5 - 1.5 * b[1].wi.x.abs()).abs() < 1e-6);
        assert!((b[1].scale.x - 1.0 / 2.25).abs() < 1e-6);
        let photon: Vec<Branch> = glass.specular_branches(wo, true, Transport::Importance).iter().copied().collect();
        assert_eq!(photon[1].scale, Color::ONE);
        let grazing = Vec3::new(0.9, 0.0, 0.19f32.sqrt());
        let inside: Vec<Branch> =
            glass.specular_branches(grazing, false, Transport::Radiance).iter().copied().collect();
        assert_eq!(inside.len(), 1);
        assert_eq!(inside[0].prob, 1.0);
    }

    #[test]
    fn what_photon_mapping_asks_of_each_material() {
        let [lambert, mirror, glass, phong] = materials().try_into().unwrap();
        assert_eq!(lambert.diffuse_rho(), Some(Color::new(0.8, 0.5, 0.2)));
        assert!((lambert.photon_survival() - 0.8).abs() < 1e-6);
        assert!(mirror.diffuse_rho().is_none() && mirror.is_specular() && mirror.photon_survival() == 1.0);
        assert!(glass.has_specular_lobe() && glass.absorption().is_none());
        assert!(phong.has_specular_lobe() && phong.glossy().is_some() && phong.diffuse_rho().is_some());
        assert!(Material::Lambertian { rho: Color::ZERO }.diffuse_rho().is_none());
        assert!(Material::Emitter
            .sample(Vec3::Z, true, Transport::Radiance, &mut stream(1, Domain::Camera, 0))
            .is_none());
    }
}
