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

/// Unpolarised Fresnel reflectance of a conductor of complex index
/// `eta` + i `k` (relative to the outside), per channel, for light arriving
/// at `cos_i` in [0, 1]: the mean of the s- and p-polarised reflectances in
/// the closed form of Moeller (Optics, 1988), which Mitsuba 3 uses
/// (`fresnel_conductor`). eta = 0, k = 1 reflects everything.
pub fn fresnel_conductor(cos_i: f32, eta: Vec3, k: Vec3) -> Vec3 {
    let c2 = (cos_i * cos_i).clamp(0.0, 1.0);
    let s2 = 1.0 - c2;
    let one = |eta: f32, k: f32| {
        let t1 = eta * eta - k * k - s2;
        let a2b2 = (t1 * t1 + 4.0 * eta * eta * k * k).max(0.0).sqrt();
        let a = (0.5 * (a2b2 + t1)).max(0.0).sqrt();
        let (t_1, t_2) = (a2b2 + c2, 2.0 * cos_i.clamp(0.0, 1.0) * a);
        let rs = (t_1 - t_2) / (t_1 + t_2);
        let (t_3, t_4) = (a2b2 * c2 + s2 * s2, t_2 * s2);
        let rp = rs * (t_3 - t_4) / (t_3 + t_4);
        let r = 0.5 * (rs + rp);
        if r.is_finite() {
            r.clamp(0.0, 1.0)
        } else {
            1.0
        }
    };
    Vec3::new(one(eta.x, k.x), one(eta.y, k.y), one(eta.z, k.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A conductor of k = 0 is a dielectric; eta = 0, k = 1 a perfect
    /// mirror; gold's normal reflectance is ((n-1)^2 + k^2) / ((n+1)^2 + k^2).
    #[test]
    fn conductor_fresnel_limits() {
        for i in 0..=20 {
            let c = i as f32 / 20.0;
            let f = fresnel_conductor(c, Vec3::splat(1.5), Vec3::ZERO);
            assert!(
                (f.x - fresnel_dielectric(c, 1.0, 1.5)).abs() < 1e-5,
                "{c}: {f} vs {}",
                fresnel_dielectric(c, 1.0, 1.5)
            );
            assert!((fresnel_conductor(c, Vec3::ZERO, Vec3::ONE).x - 1.0).abs() < 1e-6);
        }
        let (n, k) = (0.18f32, 3.1f32);
        let want = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        assert!((fresnel_conductor(1.0, Vec3::splat(n), Vec3::splat(k)).x - want).abs() < 1e-5);
    }

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
