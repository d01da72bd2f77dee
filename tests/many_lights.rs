//! Many lights drawn from the light hierarchy (issue 44, item 2): where
//! lights are spread out, each point is lit mostly by the few near it, and
//! drawing lights by their power alone (what direct light did before)
//! spends most shadow rays on far lights that send little.

use glam::Vec3;
use photonmap::light::{AreaLight, Emitting, Light, LightSampler};
use photonmap::math::Color;
use photonmap::sampling::{next_2d, stream, Domain};
use photonmap::shape::Disk;

/// 1,000 equal disks facing down over a 9 x 10 ceiling (the default
/// room's), 5 above the floor, as in examples/many_lights.rs.
fn spread_lights() -> Vec<Light> {
    (0..1000)
        .map(|k| {
            let (x, y) = (1.0 + 9.0 * ((k % 40) as f32 + 0.5) / 40.0, -5.0 + 10.0 * ((k / 40) as f32 + 0.5) / 25.0);
            let disk = Disk { center: Vec3::new(x, y, 4.999), normal: -Vec3::Z, radius: 0.05 };
            Light::Area(AreaLight::new(Emitting::Disk(disk), Color::splat(4000.0), k))
        })
        .collect()
}

/// The mean and variance of one draw's estimate of the irradiance at `p`
/// (facing up; visibility aside) when light `i` is drawn with chance
/// `chance(i)` and then sampled once.
fn one_draw(lights: &[Light], p: Vec3, draw: impl Fn(f64) -> Option<(usize, f32)>, seed: u64) -> (f64, f64) {
    let mut rng = stream(seed, Domain::Camera, 0);
    let runs = 100_000;
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for k in 0..runs {
        let u = (k as f64 + 0.5) / runs as f64;
        let e = draw(u).map_or(0.0, |(i, chance)| {
            lights[i]
                .sample_li(p, Vec3::Z, next_2d(&mut rng))
                .map_or(0.0, |inc| (inc.intensity.x * inc.dir.z.max(0.0)) as f64 / chance as f64)
        });
        sum += e;
        sum2 += e * e;
    }
    let mean = sum / runs as f64;
    (mean, sum2 / runs as f64 - mean * mean)
}

/// At points of the floor and of a wall, the hierarchy's estimate agrees
/// with drawing by power in the mean and has at most a fifth of its
/// variance (3-8% measured).
#[test]
fn the_hierarchy_draws_near_lights_with_a_fraction_of_the_variance_of_drawing_by_power() {
    let lights = spread_lights();
    let tree = LightSampler::new(&lights, 16.0);
    let n = lights.len();
    for (j, p) in
        [Vec3::new(3.0, -2.0, -4.99), Vec3::new(8.0, 3.0, -4.99), Vec3::new(5.5, 0.0, 0.0)].into_iter().enumerate()
    {
        let by_power = |u: f64| Some((((u * n as f64) as usize).min(n - 1), 1.0 / n as f32));
        let (m_power, v_power) = one_draw(&lights, p, by_power, j as u64);
        let (m_tree, v_tree) = one_draw(&lights, p, |u| tree.sample(p, Vec3::Z, u), j as u64);
        let se = ((v_power + v_tree) / 100_000.0).sqrt();
        assert!((m_tree - m_power).abs() < 5.0 * se, "{p}: means {m_tree} and {m_power} ± {se}");
        assert!(v_tree < 0.2 * v_power, "{p}: variance {v_tree} against {v_power} by power");
    }
}
