//! The scene: primitives with materials, lights, the camera, and what the
//! renderer derives from them once (bounds, the specular objects photons are
//! aimed at). [`Scene::tncg15`] builds the built-in default scene, the TNCG15
//! hexagonal room of `notes/default-scene.md`, number for number.

use crate::accel::Accel;
use crate::camera::Camera;
use crate::light::{AreaLight, Light};
use crate::material::Material;
use crate::math::{max_component, Color, Ray, Vertex};
use crate::sampling::Discrete;
pub mod file;
mod hit;
pub mod mesh;
pub mod mitsuba;
pub mod ply;
pub mod procedural;
mod room;
pub mod serialized;
mod texturing;
pub mod vol;

pub use hit::Hit;
pub use room::{tncg15_room, Eye};
pub use texturing::Texturing;

use crate::shape::{Departure, Shape, ShapeHit};
use glam::{Vec2, Vec3};

/// One primitive: its geometry, the index of its material, and the object
/// it belongs to (a mesh, a sphere, the room: what a scene file lists as
/// one shape).
#[derive(Clone, Debug)]
pub struct Prim {
    pub shape: Shape,
    pub material: u32,
    pub object: u32,
}

pub struct Scene {
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    /// The Whitted course's ambient light A (photonmap requires zero).
    pub ambient: Color,
    pub camera: Camera,
    /// Per primitive: the index of its material, and of its area light
    /// ([`NO_LIGHT`] for non-emitters). The shapes themselves live in the
    /// accelerator, in the order it visits them.
    prim_material: Vec<u32>,
    prim_light: Vec<u32>,
    /// Vertex normals of the smooth triangles ([`crate::shape::Triangle::shading`]),
    /// in 32 bits each ([`crate::math::encode_unit`]).
    shading_normals: Vec<[u32; 3]>,
    accel: Accel,
    bounds: (Vec3, Vec3),
    /// Per primitive, its object (a scene file's shape, an emitter's
    /// surface): what caustic photons aim at is an object
    /// ([`crate::photon::aims`]).
    prim_object: Vec<u32>,
    /// The lights by power (largest channel): the photon passes' choice.
    light_pick: Option<Discrete>,
    /// With many lights, the hierarchy shadow rays choose them by.
    light_tree: Option<Box<crate::light::LightSampler>>,
    /// Per material, the material seen from behind its geometric normal
    /// (itself where two-sided); empty where every material is.
    back_material: Vec<u32>,
    pub paths: PathLimits,
    /// The lights a ray leaving the scene meets (light from everywhere).
    at_infinity: Vec<u32>,
    /// Textures and the materials that read them; `None` in a scene
    /// without textures, which then pays nothing for them.
    texturing: Option<Box<Texturing>>,
    /// Participating media; `None` in a scene without, which then pays
    /// nothing for them.
    media: Option<Box<crate::medium::Media>>,
}

/// Marks a primitive that is not a light's surface.
const NO_LIGHT: u32 = u32::MAX;

/// More lights than this are drawn from the light hierarchy for direct
/// light, not visited one by one ([`Scene::many_lights`]).
pub const MANY_LIGHTS: usize = 64;

/// A scene's ingredients, before [`Scene::from_parts`] derives what the
/// renderer needs from them.
#[derive(Clone, Debug)]
pub struct SceneParts {
    pub prims: Vec<Prim>,
    /// Vertex normals of smooth triangles, indexed by their `shading`.
    pub shading_normals: Vec<[Vec3; 3]>,
    pub materials: Vec<Material>,
    /// The lights as the scene describes them; [`Scene::from_parts`]
    /// places them.
    pub lights: Vec<Light>,
    pub ambient: Color,
    pub camera: Camera,
    /// Per material: whether it reflects only on the front of the
    /// geometric normal, black behind (Mitsuba's BSDFs but `twosided` and
    /// the dielectrics). Empty: every material is two-sided.
    pub one_sided: Vec<bool>,
    pub paths: PathLimits,
    /// Textures (empty: none).
    pub texturing: Texturing,
    /// Participating media and the shapes that bound them (empty: none).
    pub media: crate::medium::MediaParts,
}

/// What the scene says of the light paths to render (Mitsuba's
/// integrator's `max_depth` and `hide_emitters`); the defaults are every
/// path, lights seen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PathLimits {
    /// The most vertices a path may have after the eye: 1 is lights seen
    /// directly, 2 adds direct light; `None`: unlimited.
    pub max_depth: Option<u32>,
    /// Lights seen directly from the eye are black.
    pub hide_emitters: bool,
}

impl SceneParts {
    /// The same scene with every length multiplied by `s` (> 0). Radiance is
    /// per unit area and solid angle, so the image is unchanged.
    pub fn scaled(mut self, s: f32) -> Self {
        for p in &mut self.prims {
            p.shape = p.shape.scaled(s);
        }
        for l in &mut self.lights {
            l.moved(Vec3::ZERO, s);
        }
        let shrink = glam::Affine3A::from_scale(Vec3::splat(1.0 / s));
        for f in &mut self.texturing.frames {
            *f *= shrink;
        }
        self.camera = self.camera.scaled(s);
        for m in &mut self.media.media {
            *m = m.scaled(s);
        }
        self
    }
}

/// Each blend's summary from its materials' (blends nest: a blend's
/// materials are summarised first).
fn blend_summaries(materials: &mut [Material], texturing: &Texturing) {
    use crate::material::{Blend, Textured};
    fn summary(m: usize, materials: &[Material], texturing: &Texturing, depth: u32) -> Material {
        match texturing.materials.get(m) {
            Some(Some(Textured::Blend { weight, first, second })) if depth < 64 => {
                let w = weight.mean(&texturing.textures).x.clamp(0.0, 1.0);
                let a = summary(*first as usize, materials, texturing, depth + 1);
                let b = summary(*second as usize, materials, texturing, depth + 1);
                Material::Blend(Blend::of(w, &a, &b))
            }
            _ => materials[m],
        }
    }
    for m in 0..materials.len() {
        if matches!(texturing.materials.get(m), Some(Some(Textured::Blend { .. }))) {
            materials[m] = summary(m, materials, texturing, 0);
        }
    }
}

/// The media of a scene's parts, with an interface per primitive of the
/// scene (`prims` of the parts', then the area lights' in the order of
/// their specs): `None` where the scene has no media, or nothing
/// refers to them.
fn place_media(
    parts: crate::medium::MediaParts,
    parts_prims: usize,
    prims: usize,
    specs: &[Light],
) -> Option<Box<crate::medium::Media>> {
    let crate::medium::MediaParts { media, prims: mut interfaces, lights, camera } = parts;
    if media.is_empty() {
        return None;
    }
    interfaces.resize(parts_prims, None);
    let area_lights = specs.iter().enumerate().filter(|(_, s)| matches!(s, Light::Area(_)));
    for (i, _) in area_lights {
        interfaces.push(lights.get(i).copied().flatten());
    }
    interfaces.resize(prims, None);
    let used = camera.is_some() || interfaces.iter().any(Option::is_some);
    used.then(|| Box::new(crate::medium::Media::new(media, interfaces, camera)))
}

impl Scene {
    /// Assembles a scene; the area lights are added as primitives too (after
    /// `parts.prims`, in order), so that camera rays see them and photons are
    /// absorbed by them.
    pub fn from_parts(parts: SceneParts) -> Self {
        let SceneParts {
            mut prims,
            shading_normals,
            mut materials,
            lights: specs,
            ambient,
            camera,
            one_sided,
            paths,
            texturing,
            media,
        } = parts;
        // A textured material is its typical self wherever the scene asks
        // about it as a whole; a blend, what its materials are together.
        for (m, t) in materials.iter_mut().zip(&texturing.materials) {
            if let Some(t) = t {
                *m = t.typical(&texturing.textures);
            }
        }
        blend_summaries(&mut materials, &texturing);
        let mut texturing = texturing;
        let light_patterns = std::mem::take(&mut texturing.light_patterns);
        let texturing = texturing.is_used().then(|| Box::new(texturing));
        // A one-sided material's back is a black surface of its own.
        let mut back_material = if one_sided.iter().any(|&b| b) {
            let count = materials.len();
            let mut backs = Vec::with_capacity(count);
            for m in 0..count {
                if one_sided.get(m) != Some(&true) {
                    backs.push(m as u32);
                    continue;
                }
                let back = materials[m].back_side();
                let i = match materials[count..].iter().position(|b| *b == back) {
                    Some(i) => count + i,
                    None => {
                        materials.push(back);
                        materials.len() - 1
                    }
                };
                backs.push(i as u32);
            }
            backs
        } else {
            Vec::new()
        };
        let parts_prims = prims.len();
        let mut prim_light = vec![NO_LIGHT; prims.len()];
        let mut lights = Vec::new();
        let emitter = materials.len() as u32;
        if specs.iter().any(|l| matches!(l, Light::Area(a) if a.material.is_none())) {
            materials.push(Material::Emitter);
            // Seen from either side the same: every material has its entry
            // where any is one-sided (the backs themselves included).
            if !back_material.is_empty() {
                back_material.extend(back_material.len() as u32..materials.len() as u32);
            }
        }
        let objects = prims.iter().map(|p| p.object + 1).max().unwrap_or(0);
        for (i, spec) in specs.iter().enumerate() {
            if let Light::Area(a) = spec {
                let prim = prims.len() as u32;
                let material = a.material.unwrap_or(emitter);
                prims.push(Prim { shape: a.surface.shape(), material, object: objects + lights.len() as u32 });
                prim_light.push(lights.len() as u32);
                lights.push(Light::Area(a.placed(prim, light_patterns.get(i).cloned().flatten())));
            }
        }
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for p in &prims {
            let (a, b) = p.shape.bounds();
            lo = lo.min(a);
            hi = hi.max(b);
        }
        let media = place_media(media, parts_prims, prims.len(), &specs);
        lights.extend(specs.into_iter().filter(|l| l.area().is_none()));
        // Light from infinity starts its photons outside everything else.
        let (lo, hi) = crate::light::place_lights(&mut lights, lo, hi);
        let at_infinity = (0..lights.len() as u32)
            .filter(|&i| lights[i as usize].bounds().is_none() && !lights[i as usize].is_delta())
            .collect();
        // Lights stay out of the enclosure: their hits must name them.
        let group: Vec<Option<u32>> =
            prims.iter().zip(&prim_light).map(|(p, &l)| (l == NO_LIGHT).then_some(p.material)).collect();
        let prim_material = prims.iter().map(|p| p.material).collect();
        let prim_object = prims.iter().map(|p| p.object).collect();
        let accel = Accel::with_enclosure(prims.into_iter().map(|p| p.shape).collect(), &group);
        let light_pick = Discrete::new(lights.iter().map(|l| max_component(l.power()) as f64));
        let light_tree = (lights.len() > MANY_LIGHTS)
            .then(|| Box::new(crate::light::LightSampler::new(&lights, (hi - lo).length())));
        Scene {
            materials,
            lights,
            ambient,
            camera,
            prim_material,
            prim_light,
            shading_normals: shading_normals.iter().map(|n| n.map(crate::math::encode_unit)).collect(),
            accel,
            bounds: (lo, hi),
            prim_object,
            light_pick,
            light_tree,
            back_material,
            paths,
            at_infinity,
            texturing,
            media,
        }
    }

    /// The scene's participating media, if it has any.
    #[inline]
    pub fn media(&self) -> Option<&crate::medium::Media> {
        self.media.as_deref()
    }

    /// The indices of the lights at infinity (light from everywhere).
    #[inline]
    pub fn lights_at_infinity(&self) -> &[u32] {
        &self.at_infinity
    }

    /// Radiance arriving along a ray travelling along `dir` that leaves the
    /// scene (light from everywhere; black without it).
    #[inline]
    pub fn background(&self, dir: Vec3) -> Color {
        let mut sum = Color::ZERO;
        for &i in &self.at_infinity {
            sum += self.lights[i as usize].radiance_from_infinity(dir);
        }
        sum
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray, departure: Option<Departure>) -> Option<Hit> {
        self.intersect_within(ray, departure, f32::INFINITY)
    }

    /// The nearest hit closer than `t_max`.
    #[inline]
    pub fn intersect_within(&self, ray: &Ray, departure: Option<Departure>, t_max: f32) -> Option<Hit> {
        self.accel.closest_hit(ray, departure, t_max).map(|(prim, h)| {
            let mut hit = Hit {
                t: h.t,
                point: h.point,
                p_err: h.p_err,
                normal: h.normal,
                shading_normal: self.shading_normal(&h),
                prim,
                bary: Vec2::from_array(h.uv),
                tangent: Vec3::ZERO,
            };
            if let Some(t) = &self.texturing {
                t.shade(&mut hit, self.accel.shape(prim), self.prim_material[prim as usize]);
            }
            hit
        })
    }

    /// A hit's vertex normals interpolated at its barycentrics, or the
    /// geometric normal where there are none or the interpolation points
    /// across the surface (the normals were oriented with the triangles'
    /// winding when the mesh was read).
    #[inline]
    fn shading_normal(&self, h: &ShapeHit) -> Vec3 {
        let Some(&codes) = self.shading_normals.get(h.shading as usize) else {
            return h.shading_normal.unwrap_or(h.normal);
        };
        let [n0, n1, n2] = codes.map(crate::math::decode_unit);
        let [u, v] = h.uv;
        match ((1.0 - u - v) * n0 + u * n1 + v * n2).try_normalize() {
            Some(n) if n.dot(h.normal) > 0.0 => n,
            _ => h.normal,
        }
    }

    /// Bytes the scene's geometry holds: the shapes and the accelerator,
    /// the per-primitive material and light, the vertex normals.
    pub fn memory_bytes(&self) -> usize {
        self.accel.memory_bytes()
            + (self.prim_material.capacity() + self.prim_light.capacity() + self.prim_object.capacity()) * 4
            + self.shading_normals.capacity() * std::mem::size_of::<[u32; 3]>()
    }

    /// Number of primitives (the area lights' surfaces included).
    pub fn prim_count(&self) -> usize {
        self.prim_material.len()
    }

    /// The geometry of primitive `prim`.
    pub fn shape(&self, prim: u32) -> &Shape {
        self.accel.shape(prim)
    }

    /// Whether the segment from the ray's origin to `t_max` is blocked by
    /// anything but primitive `ignore` (the light being aimed at).
    pub fn occluded(&self, ray: &Ray, departure: Option<Departure>, t_max: f32, ignore: Option<u32>) -> bool {
        self.accel.occluded(ray, departure, t_max, ignore)
    }

    /// The material a ray travelling along `dir` meets at `hit`: a one-sided
    /// material's black back where it arrives behind the geometric normal;
    /// where the primitive's material is a blend, one of its materials
    /// ([`crate::material::Blend`]).
    #[inline]
    pub fn material_seen(&self, hit: &Hit, dir: Vec3) -> Material {
        let mut m = self.prim_material[hit.prim as usize] as usize;
        if let Some(t) = &self.texturing {
            m = t.pick(hit, dir, m);
            let back = self.seen_from_behind(hit, dir, m);
            if let Some(Some(recipe)) = t.materials.get(m) {
                let material = recipe.at(&t.point(hit), &t.textures);
                return if back { material.back_side() } else { material };
            }
            return self.materials[if back { self.back_material[m] as usize } else { m }];
        }
        if self.seen_from_behind(hit, dir, m) {
            self.materials[self.back_material[m] as usize]
        } else {
            self.materials[m]
        }
    }

    /// Whether material `m` is one-sided and `dir` arrives behind it.
    #[inline]
    fn seen_from_behind(&self, hit: &Hit, dir: Vec3, m: usize) -> bool {
        !(self.back_material.is_empty() || dir.dot(hit.normal) < 0.0) && self.back_material[m] as usize != m
    }

    /// Whether a photon arriving at `hit`, where it meets `seen`, is
    /// stored: where `seen` has a diffuse lobe, and where the primitive's
    /// material is a blend with a diffuse lobe in either of its materials,
    /// whichever the photon met ([`crate::material::Blend`]).
    #[inline]
    pub fn stores_photons(&self, hit: &Hit, seen: &Material) -> bool {
        seen.diffuse_rho().is_some()
            || (self.texturing.is_some()
                && matches!(self.materials[self.prim_material[hit.prim as usize] as usize], Material::Blend(b) if b.diffuse.is_some()))
    }

    pub fn material(&self, prim: u32) -> &Material {
        &self.materials[self.prim_material[prim as usize] as usize]
    }

    /// Radiance that the surface met at `hit` emits itself towards `-dir`
    /// (zero unless it is the surface of an area light).
    #[inline]
    pub fn emitted(&self, hit: &Hit, dir: Vec3) -> Color {
        self.light_of(hit.prim).map_or(Color::ZERO, |l| {
            if dir.dot(l.surface.normal()) < 0.0 {
                l.radiance_at(hit.bary)
            } else {
                Color::ZERO
            }
        })
    }

    /// The area light whose surface primitive `prim` is.
    pub fn light_of(&self, prim: u32) -> Option<&AreaLight> {
        match self.prim_light[prim as usize] {
            NO_LIGHT => None,
            i => self.lights[i as usize].area(),
        }
    }

    /// What is left of light that travelled `t` from a ray's `departure`:
    /// less than one only inside absorbing glass (Beer–Lambert). A ray is
    /// inside a glass body when it left the glass against its outward normal.
    pub fn transmittance(&self, departure: Option<Departure>, t: f32) -> Color {
        match departure.filter(|d| !d.outward).and_then(|d| self.material(d.prim).absorption()) {
            Some(absorption) => (-absorption * t).exp(),
            None => Color::ONE,
        }
    }

    /// Where the camera's pixel-centre rays at `width` x `height` first meet
    /// a diffuse surface: (point, normal towards the camera). The lookups of
    /// the estimator benches and tests.
    pub fn diffuse_hits(&self, width: u32, height: u32) -> Vec<(Vertex, Vec3)> {
        let camera = self.camera.with_resolution(width, height);
        (0..width * height)
            .filter_map(|i| {
                let ray = camera.ray(i % width, i / width, Vec2::splat(0.5));
                let hit = self.intersect(&ray, None)?;
                self.material(hit.prim).diffuse_rho()?;
                Some((hit.point, hit.facing_normal(ray.dir)))
            })
            .collect()
    }

    /// Axis-aligned bounds of all primitives.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    /// Length of the bounds' diagonal: the scene's scale, for scale-free defaults.
    pub fn diagonal(&self) -> f32 {
        (self.bounds.1 - self.bounds.0).length()
    }

    /// The object primitive `prim` belongs to.
    pub fn object(&self, prim: u32) -> u32 {
        self.prim_object[prim as usize]
    }

    /// Whether direct light draws lights from the light hierarchy rather
    /// than visiting each: a scene of more than [`MANY_LIGHTS`] (an
    /// emissive mesh is a light per triangle), where visiting each would
    /// cost their number.
    #[inline]
    pub fn many_lights(&self) -> bool {
        self.light_tree.is_some()
    }

    /// With many lights, a light for a shadow ray at `p` on a surface
    /// facing `n` chosen from the hierarchy by `u` in [0, 1), and the chance
    /// of that choice; `None` where no light sends anything there.
    #[inline]
    pub fn sample_light(&self, p: Vec3, n: Vec3, u: f64) -> Option<(usize, f32)> {
        self.light_tree.as_ref()?.sample(p, n, u)
    }

    /// The index of a light chosen by `u` in [0, 1) in proportion to its
    /// power, and the chance of that choice.
    #[inline]
    pub fn pick_light_index(&self, u: f32) -> Option<(usize, f32)> {
        let lights = self.light_pick.as_ref()?;
        let i = lights.sample(u).0;
        let p = lights.prob(i);
        (p > 0.0).then_some((i, p))
    }

    /// The chance that [`Self::pick_light_index`] picks light `index`.
    #[inline]
    pub fn light_prob(&self, index: usize) -> f32 {
        self.light_pick.as_ref().map_or(0.0, |l| l.prob(index))
    }

    /// What light `index`'s own sampling density is multiplied by in the
    /// density of the shadow rays at `p` (facing `n`) that takes `count`
    /// of them per light: `count` (1 for a delta light), or with many
    /// lights the draws ([`crate::light::draws`]) times the chance that a
    /// draw at `p` picks it.
    #[inline]
    pub fn light_share(&self, index: usize, count: u32, p: Vec3, n: Vec3) -> f32 {
        if let Some(tree) = &self.light_tree {
            return crate::light::draws(count) as f32 * tree.pmf(p, n, index);
        }
        if self.lights[index].is_delta() {
            1.0
        } else {
            count as f32
        }
    }

    /// The index of the area light whose surface primitive `prim` is.
    pub fn light_index_of(&self, prim: u32) -> Option<usize> {
        match self.prim_light[prim as usize] {
            NO_LIGHT => None,
            i => Some(i as usize),
        }
    }

    /// A light chosen by `u` in [0, 1) in proportion to its power (largest
    /// channel), with the probability of that choice; `None` when no light
    /// emits anything.
    #[inline]
    pub fn pick_light(&self, u: f32) -> Option<(&Light, f32)> {
        let lights = self.light_pick.as_ref()?;
        let i = lights.sample(u).0;
        let p = lights.prob(i);
        (p > 0.0).then(|| (&self.lights[i], p))
    }

    /// Total emitted power per channel.
    pub fn emitted_power(&self) -> Color {
        self.lights.iter().map(|l| l.power()).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{cosine_hemisphere, next_2d, stream, uniform_cone, Domain};

    /// Rays spawned from surfaces of the default scene, in both hemispheres
    /// and at grazing angles, never re-hit their own surface near the origin,
    /// and a ray leaving the glass sphere inwards meets its far side at the
    /// chord length.
    #[test]
    fn spawned_rays_never_rehit_their_own_surface() {
        let scene = Scene::tncg15(Eye::One);
        let mut rng = stream(8, Domain::Camera, 4);
        // Rays spawned back to the side they arrived from (in a closed room)
        // that met nothing, and rays that met the sphere they left.
        let (mut back, mut escaped, mut sphere_rehits) = (0, 0, 0);
        for _ in 0..20_000 {
            let o = Vec3::new(
                1.0 + 10.0 * next_2d(&mut rng).x,
                -4.0 + 8.0 * next_2d(&mut rng).x,
                -4.0 + 8.0 * next_2d(&mut rng).y,
            );
            let arriving = uniform_cone(next_2d(&mut rng), -1.0);
            let Some(hit) = scene.intersect(&Ray::new(o, arriving), None) else {
                continue;
            };
            for kind in 0..3 {
                let mut d = uniform_cone(next_2d(&mut rng), -1.0);
                if kind == 1 {
                    // Nearly tangent to the surface, on either side.
                    d = (d - hit.normal * d.dot(hit.normal) * 0.9999).normalize();
                } else if kind == 2 {
                    // A photon's diffuse bounce as the pass makes it: the
                    // frame's image of a cosine sample, not renormalised.
                    let n = hit.facing_normal(arriving);
                    d = crate::math::Frame::from_normal(n).to_world(cosine_hemisphere(next_2d(&mut rng)));
                }
                let (ray, dep) = hit.spawn(d);
                let arrival_side = d.dot(hit.facing_normal(arriving)) > 0.0;
                back += arrival_side as u32;
                let next = scene.intersect(&ray, Some(dep));
                // Every origin lies inside the room, so the side a ray
                // arrived from is enclosed: a ray going back must meet
                // something (a miss: it leaked out of the room).
                escaped += (arrival_side && next.is_none()) as u32;
                if let Some(next) = next {
                    if next.prim == hit.prim {
                        sphere_rehits += 1;
                        let Shape::Sphere(s) = *scene.shape(hit.prim) else {
                            panic!("re-hit flat primitive {} at t = {}", hit.prim, next.t)
                        };
                        assert!(!dep.outward, "left a sphere outwards and met it again");
                        let cos = -d.dot(hit.normal);
                        let chord = 2.0 * s.radius * cos;
                        // The origin sits up to |p_err| inside the surface; from
                        // there a tangent chord is up to sqrt(8 r |p_err|) long.
                        let slack = (8.0 * s.radius * hit.p_err.length()).sqrt() + 1e-4 * s.radius;
                        assert!(
                            (next.t - chord).abs() < slack.max(1e-3 * s.radius * (cos > 0.01) as i32 as f32),
                            "t {} vs chord {chord} (cos {cos})",
                            next.t
                        );
                        assert!(next.normal.dot(d) >= -1e-3, "the far side is where the ray exits");
                    }
                }
            }
        }
        assert_eq!(escaped, 0, "{escaped} of {back} rays spawned back to their arrival side met nothing");
        // Half the directions go back (kind 2 always does).
        assert!(back > 30_000, "{back}");
        assert!(sphere_rehits > 100, "the sphere's chords were checked {sphere_rehits} times");
    }

    /// The part of an estimate's disk on its surface: all of it on the open
    /// floor, half of it at a wall's foot, a quarter in a corner of the
    /// room; less where the tetrahedron stands on the floor.
    #[test]
    fn default_scene_is_the_spec() {
        let scene = Scene::tncg15(Eye::One);
        // 24 room triangles + glass + mirror + 4 tetrahedron faces + the light.
        assert_eq!(scene.prim_count(), 31);
        assert_eq!(scene.lights.len(), 1);
        let phi = scene.emitted_power();
        assert!((phi.x - std::f32::consts::PI.powi(2) * 10.0).abs() < 1e-3);
        // Every room normal points into the room: from the room's centre each
        // triangle's front faces the centre.
        for prim in 0..24 {
            let Shape::Triangle(t) = *scene.shape(prim) else { panic!() };
            assert!(t.normal.dot(Vec3::new(5.0, 0.0, 0.0) - t.v0) > 0.0);
            assert!((t.area() - 0.0).abs() > 1.0);
        }
        let (lo, hi) = scene.bounds();
        assert_eq!((lo, hi), (Vec3::new(-3.0, -6.0, -5.0), Vec3::new(13.0, 6.0, 5.0)));
        assert_eq!(crate::photon::aims::specular_targets(&scene).len(), 2);
    }
}
