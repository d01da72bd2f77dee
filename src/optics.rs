//! Reflection, refraction and the Fresnel equations, as pure functions in the
//! local frame of the surface (the normal is local +z, and the incident
//! direction `wi` points away from the surface, on the +z side).

use glam::Vec3;

/// Mirror reflection about the local normal.
pub fn reflect(wi: Vec3) -> Vec3 {
    Vec3::new(-wi.x, -wi.y, wi.z)
}

/// Snell refraction of `wi` (with `wi.z > 0`) into the far side, `eta` being
/// n_incident / n_transmitted. `None` on total internal reflection. Unit to
/// rounding where `wi` is (not normalised: every caller maps it to world
/// space and normalises there).
pub fn refract(wi: Vec3, eta: f32) -> Option<Vec3> {
    let sin2_t = eta * eta * (1.0 - wi.z * wi.z).max(0.0);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(Vec3::new(-eta * wi.x, -eta * wi.y, -cos_t))
}

/// Exact unpolarised Fresnel reflectance of a smooth dielectric boundary for
/// light arriving at `cos_i` (> 0) from the side of index `n_i` towards index
/// `n_t`: the mean of the s- and p-polarised reflectances. Returns 1 past the
/// critical angle (total internal reflection).
pub fn fresnel_dielectric(cos_i: f32, n_i: f32, n_t: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = (n_i / n_t).powi(2) * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (n_i * cos_i - n_t * cos_t) / (n_i * cos_i + n_t * cos_t);
    let rp = (n_t * cos_i - n_i * cos_t) / (n_t * cos_i + n_i * cos_t);
    0.5 * (rs * rs + rp * rp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_glass_reflects_four_percent() {
        assert!((fresnel_dielectric(1.0, 1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(1.0, 1.5, 1.0) - 0.04).abs() < 1e-6);
    }

    #[test]
    fn reflectance_plus_transmittance_is_one_and_bounded() {
        for i in 0..=1000 {
            let c = i as f32 / 1000.0;
            for (a, b) in [(1.0, 1.5), (1.5, 1.0), (1.0, 2.4), (1.33, 1.0)] {
                let r = fresnel_dielectric(c, a, b);
                let t = 1.0 - r;
                assert!((0.0..=1.0).contains(&r) && (r + t - 1.0).abs() < 1e-7, "{c} {a} {b} {r}");
            }
        }
        // Grazing incidence reflects everything.
        assert!(fresnel_dielectric(0.0, 1.0, 1.5) > 0.999);
    }

    #[test]
    fn total_internal_reflection_past_the_critical_angle() {
        let critical = (1.0f32 / 1.5).asin();
        let just_past = (critical + 1e-3).cos();
        let just_before = (critical - 1e-3).cos();
        assert_eq!(fresnel_dielectric(just_past, 1.5, 1.0), 1.0);
        assert!(fresnel_dielectric(just_before, 1.5, 1.0) < 1.0);
        let wi = Vec3::new((critical + 1e-3).sin(), 0.0, just_past);
        assert!(refract(wi, 1.5).is_none());
        assert!(refract(Vec3::new((critical - 1e-3).sin(), 0.0, just_before), 1.5).is_some());
    }

    #[test]
    fn refraction_obeys_snell() {
        let theta_i = 0.7f32;
        let wi = Vec3::new(theta_i.sin(), 0.0, theta_i.cos());
        let wt = refract(wi, 1.0 / 1.5).unwrap();
        let sin_t = (wt.x * wt.x + wt.y * wt.y).sqrt();
        assert!((theta_i.sin() - 1.5 * sin_t).abs() < 1e-6);
        assert!(wt.z < 0.0 && (wt.length() - 1.0).abs() < 1e-6);
        // Index 1 is no interface at all.
        let straight = refract(wi, 1.0).unwrap();
        assert!((straight - Vec3::new(-wi.x, -wi.y, -wi.z)).length() < 1e-6);
        assert_eq!(reflect(wi), Vec3::new(-wi.x, 0.0, wi.z));
    }
}
