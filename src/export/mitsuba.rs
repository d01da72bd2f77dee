//! A scene as Mitsuba 3 renders it: XML for the camera, materials, lights
//! and analytic shapes, binary PLY for the triangle meshes. What has a
//! faithful equivalent is written; what has none is refused with its place
//! in the scene file, never approximated silently:
//!
//! | photonmap | Mitsuba 3 |
//! |---|---|
//! | camera (corners or look-at) | `perspective`, off-centre by `principal_point_offset_x/y`; a thin lens as `thinlens`, an orthographic camera as `orthographic` (module `mitsuba_sensor`); a plane that is not a rectangle of square pixels, a mirrored one, or an off-centre thin lens is refused |
//! | triangles, meshes, tetrahedra, the room | `ply` meshes (vertex normals where the mesh is smooth, `face_normals` otherwise; every `mesh_attribute` texture's values as vertex properties, read as `vertex_attrN`: `mitsuba_recipe::mesh_attributes`) |
//! | sphere, disk | `sphere`, `disk` (by transform) |
//! | ellipsoid | `sphere` when the transform scales evenly (with its `to_world` where it turns or mirrors: the same texture coordinates); else a 20,480-triangle `ply` with exact normals at its vertices (Mitsuba's sphere takes no uneven scale), in a textured scene with the sphere's coordinates at them (interpolated between), and a note says so |
//! | lambertian, mirror | `twosided` `diffuse`, `twosided` `conductor` (photonmap's are two-sided) |
//! | glass | `dielectric`; absorption as a `homogeneous` interior medium (then `volpath`) |
//! | disk and triangle lights | `area` emitters (one-sided) on `disk` and `ply` shapes |
//! | directional and point (1/d^2) lights | `directional`, `point` |
//! | sky, environment map | `constant`, `envmap` (the map as a float EXR beside the meshes, already scaled; its rotation as `to_world`) |
//! | Phong; point lights of other falloffs | refused |
//!
//! The XML takes `spp`, `seed`, `width` and `height` as parameters
//! (`mi.load_file(path, spp=...)`), defaulting to 64, 0 and the camera's size.
//!
//! Positions are written relative to the camera's eye, or to a chosen
//! origin and scale ([`Placement`]). Mitsuba 3 starts a ray leaving a
//! surface (1 + max |p|) x 8.9e-5 away from it along the normal, a length
//! that grows with the distance from the origin: a glass ball of radius
//! 0.15 twenty units from the origin refracts as if 1% of its radius
//! thinner, which moves the window it shows by 0.14 pixel (the hall of the
//! scene suite). Near the eye, where what the camera resolves lies, the
//! offset is smaller; a reference that must resolve a small glass object
//! puts the origin at it and scales the scene up, so that the offset is
//! about 8.9e-5 of the distance to the origin.

use super::mitsuba_medium::interface_refs;
use super::mitsuba_sensor::sensor;
use super::ply::PlyMesh;
use crate::camera::Camera;
use crate::light::{AreaLight, Emitting, Light, MitsubaEmitter, MitsubaParam};
use crate::material::Material;
use crate::math::Color;
use crate::scene::file::{Origins, Place};
use crate::scene::procedural::icosphere;
use crate::scene::SceneParts;
use crate::shape::{Ellipsoid, Shape, FLAT};
use glam::{Affine3A, Vec2, Vec3};
use std::fmt::Write;

/// An exported scene: the XML text, the files it names (meshes and
/// environment maps: relative paths and contents), and notes on what was
/// written differently.
pub struct MitsubaScene {
    pub xml: String,
    pub meshes: Vec<(String, Vec<u8>)>,
    pub notes: Vec<String>,
}

/// What the export refuses, and where it is written (`None`: the
/// built-in scene).
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    pub place: Option<Place>,
    pub message: String,
}

impl Refusal {
    /// The refusal as a message, with the file's place where there is one.
    pub fn describe(&self, origins: Option<&Origins>) -> String {
        match (&self.place, origins) {
            (Some(p), Some(o)) => o.error(p, self.message.clone()).to_string(),
            _ => format!("the built-in scene: {}", self.message),
        }
    }
}

/// Where the exported scene lies: the point of the scene written as
/// Mitsuba's origin, and how many of Mitsuba's units a scene unit is. The
/// image is the same for every placement, up to Mitsuba's ray offsets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    pub(super) origin: Vec3,
    pub(super) scale: f32,
}

impl Placement {
    /// `origin` written as (0, 0, 0), lengths times `scale`; or why not.
    pub fn new(origin: Vec3, scale: f32) -> Result<Self, String> {
        if !origin.is_finite() {
            return Err(format!("origin {origin}: give three finite numbers"));
        }
        if !(scale > 0.0 && scale.is_finite()) {
            return Err(format!("scale {scale}: give a positive number"));
        }
        Ok(Placement { origin, scale })
    }

    /// The default: the camera's eye at the origin, lengths unchanged.
    pub fn at_eye(camera: &Camera) -> Self {
        Placement { origin: camera.eye, scale: 1.0 }
    }

    pub(super) fn point(&self, p: Vec3) -> Vec3 {
        (p - self.origin) * self.scale
    }
}

/// Writes `parts` for Mitsuba 3, its meshes named `mesh_dir/NNN.ply`.
pub fn to_mitsuba(
    parts: &SceneParts,
    origins: Option<&Origins>,
    mesh_dir: &str,
    placement: Placement,
) -> Result<MitsubaScene, Refusal> {
    let place = |f: &dyn Fn(&Origins) -> Option<&Place>| origins.and_then(f).cloned();
    let refuse = |place: Option<Place>, message: String| Refusal { place, message };
    let at = |p: Vec3| placement.point(p);
    let s = placement.scale;
    let mut out =
        Exporter { mesh_dir, xml: String::new(), meshes: Vec::new(), notes: Vec::new(), media: false, placement };
    let camera = sensor(&parts.camera, placement).map_err(|m| refuse(place(&|o| Some(&o.camera)), m))?;

    // Materials (those used), each defined once.
    let mut used = vec![false; parts.materials.len()];
    for p in &parts.prims {
        used[p.material as usize] = true;
    }
    for l in &parts.lights {
        if let Light::Area(AreaLight { material: Some(m), .. }) = l {
            used[*m as usize] = true;
        }
    }
    // A blend's materials are written too, wherever they are named.
    let mut changed = true;
    while changed {
        changed = false;
        for m in 0..used.len() {
            for k in super::mitsuba_recipe::parts_of(parts, m).filter(|_| used[m]).into_iter().flatten() {
                if !used[k as usize] {
                    used[k as usize] = true;
                    changed = true;
                }
            }
        }
    }
    let mut bsdfs = String::new();
    let mut copied = Vec::new();
    // Which materials read a mesh attribute (a blend's parts included).
    let mut reads_attributes = vec![false; parts.materials.len()];
    for (i, m) in parts.materials.iter().enumerate().filter(|(i, _)| used[*i]) {
        let id = format!("material{i}");
        let xml = if super::mitsuba_recipe::needed(parts, i) {
            let mut files = super::mitsuba_recipe::Files { dir: mesh_dir, files: &mut out.meshes, copied: &mut copied };
            super::mitsuba_recipe::element(parts, i, &id, &mut files, &bsdf)
        } else {
            bsdf(m, &id)
        };
        let xml = xml.map_err(|msg| refuse(place(&|o| o.materials.get(i)), msg))?;
        reads_attributes[i] = xml.contains("type=\"mesh_attribute\"");
        bsdfs += &xml;
        if let Material::Glass { absorption, .. } = m {
            if *absorption != Color::ZERO {
                out.media = true;
                let _ = writeln!(
                    bsdfs,
                    "    <medium type=\"homogeneous\" id=\"medium{i}\">\n        <rgb name=\"sigma_t\" value=\"{}\"/>\n        <rgb name=\"albedo\" value=\"0, 0, 0\"/>\n    </medium>",
                    rgb(*absorption / s)
                );
            }
        }
    }
    bsdfs += "    <bsdf type=\"diffuse\" id=\"black\"><rgb name=\"reflectance\" value=\"0, 0, 0\"/></bsdf>\n";
    if !parts.media.media.is_empty() {
        let (xml, files) = super::mitsuba_medium::media(&parts.media.media, mesh_dir, placement);
        bsdfs += &xml;
        out.meshes.extend(files);
        out.media = true;
    }
    let interface = |list: &[Option<crate::medium::Interface>], i: usize| list.get(i).copied().flatten();
    for _ in 0..parts.materials.len() {
        for m in 0..parts.materials.len() {
            if super::mitsuba_recipe::parts_of(parts, m)
                .is_some_and(|k| k.iter().any(|&k| reads_attributes[k as usize]))
            {
                reads_attributes[m] = true;
            }
        }
    }

    // Geometry: a mesh per run of triangles of one object, material and
    // shading; analytic shapes one by one.
    let mut shapes = String::new();
    let mut run: Option<(u32, u32, PlyMesh)> = None;
    let attributes = super::mitsuba_recipe::mesh_attributes(&parts.texturing.textures);
    let mut run_media = None;
    let refs = |m: u32, media| {
        material_refs(parts, m, media).map_err(|msg| refuse(place(&|o| o.materials.get(m as usize)), msg))
    };
    for (i, p) in parts.prims.iter().enumerate() {
        let media = interface(&parts.media.prims, i);
        if let Shape::Triangle(t) = p.shape {
            let smooth = t.shading != FLAT;
            // Coordinates of its own (a mesh's without read back as its
            // barycentrics).
            let uv = match parts.texturing.surfaces.get(i) {
                Some(crate::texture::SurfaceUv::Triangle(uv)) if *uv != [Vec2::ZERO, Vec2::X, Vec2::Y] => Some(*uv),
                _ => None,
            };
            let same = run_media == media
                && run.as_ref().is_some_and(|(o, m, mesh)| {
                    *o == p.object
                        && *m == p.material
                        && mesh.is_smooth() == smooth
                        && mesh.is_textured() == uv.is_some()
                });
            if !same {
                if let Some((_, m, mesh)) = run.take() {
                    shapes += &out.mesh(mesh, &refs(m, run_media)?, "");
                }
                let mesh = if uv.is_some() { PlyMesh::textured(smooth) } else { PlyMesh::new(smooth) };
                let mesh = mesh.with_attributes(attributes.iter().map(|a| a.0.clone()).collect());
                run = Some((p.object, p.material, mesh));
                run_media = media;
            }
            let normals = if smooth { parts.shading_normals[t.shading as usize] } else { [t.normal; 3] };
            if let Some((_, _, mesh)) = run.as_mut() {
                let value = |a: usize, k: usize| attributes[a].1.get(i).map_or(Color::ZERO, |v| v[k]);
                mesh.push_corners([t.v0, t.v1, t.v2].map(at), normals, uv.unwrap_or_default(), value);
            }
            continue;
        }
        if let Some((_, m, mesh)) = run.take() {
            shapes += &out.mesh(mesh, &refs(m, run_media)?, "");
        }
        let refs = |m: u32| refs(m, media);
        // Only the meshes carry the attributes; Mitsuba 3.9.1 refuses to
        // render a shape that lacks one its material reads (photonmap
        // reads 0 there).
        if reads_attributes[p.material as usize] {
            return Err(refuse(
                place(&|o| o.objects.get(p.object as usize)),
                format!("a {} whose material reads a mesh_attribute texture has no equivalent in Mitsuba 3 (only meshes carry attributes)", p.shape.name()),
            ));
        }
        shapes += &match &p.shape {
            Shape::Sphere(sphere) => format!(
                "    <shape type=\"sphere\">\n        <point name=\"center\" value=\"{}\"/>\n        <float name=\"radius\" value=\"{}\"/>\n{}    </shape>\n",
                xyz(at(sphere.center)),
                sphere.radius * s,
                refs(p.material)?
            ),
            Shape::Disk(d) => format!(
                "    <shape type=\"disk\">\n        {}\n{}    </shape>\n",
                disk_transform(at(d.center), d.normal, d.radius * s),
                refs(p.material)?
            ),
            Shape::Ellipsoid(e) => out.ellipsoid(e, &refs(p.material)?, parts.texturing.is_used()),
            Shape::Cylinder(c) => format!(
                "    <shape type=\"cylinder\">\n        <point name=\"p0\" value=\"{}\"/>\n        <point name=\"p1\" value=\"{}\"/>\n        <float name=\"radius\" value=\"{}\"/>\n        <boolean name=\"flip_normals\" value=\"{}\"/>\n{}    </shape>\n",
                xyz(at(c.p0)),
                xyz(at(c.p1())),
                c.radius * s,
                c.flip,
                refs(p.material)?
            ),
            Shape::Ellipse(e) => {
                let to_world = crate::shape::ellipse_to_world(e);
                let placed = glam::DAffine3::from_scale(glam::DVec3::splat(s as f64))
                    * glam::DAffine3::from_translation(-placement.origin.as_dvec3())
                    * to_world;
                let m = Affine3A::from_mat3_translation(placed.matrix3.as_mat3(), placed.translation.as_vec3());
                format!("    <shape type=\"disk\">\n        {}\n{}    </shape>\n", matrix(&m), refs(p.material)?)
            }
            Shape::Triangle(_) => unreachable!("handled above"),
            // A shape added to photonmap renders before the export knows
            // it: until an arm here writes it, exporting it is refused
            // with its place.
            #[allow(unreachable_patterns)]
            shape => {
                return Err(refuse(
                    place(&|o| o.objects.get(p.object as usize)),
                    format!("the {} has no equivalent in the Mitsuba export yet", shape.name()),
                ))
            }
        };
    }
    if let Some((_, m, mesh)) = run.take() {
        shapes += &out.mesh(mesh, &refs(m, run_media)?, "");
    }

    // Lights: area lights are shapes with an emitter (a run of emissive
    // triangles of one shape is one mesh).
    let mut emitters = String::new();
    type TriRun = (usize, Color, Option<u32>, Option<crate::medium::Interface>, PlyMesh);
    let mut tri_run: Option<TriRun> = None;
    let flush = |out: &mut Exporter, tri_run: &mut Option<TriRun>| {
        tri_run.take().map_or(String::new(), |(_, radiance, material, media, mesh)| {
            let emitter = format!(
                "        <emitter type=\"area\"><rgb name=\"radiance\" value=\"{}\"/></emitter>\n",
                rgb(radiance)
            );
            out.mesh(mesh, &(bsdf_ref(material) + &interface_refs(media)), &emitter)
        })
    };
    for (i, l) in parts.lights.iter().enumerate() {
        let light_place = || place(&|o| o.lights.get(i));
        let media = interface(&parts.media.lights, i);
        match l {
            Light::Area(AreaLight { surface: Emitting::Triangle(t), radiance, material, .. }) => {
                let (t, radiance, material) = (*t, *radiance, *material);
                let key = origins.and_then(|o| o.lights.get(i)).map_or(usize::MAX, |p| p.line);
                let same = tri_run
                    .as_ref()
                    .is_some_and(|(k, r, m, f, _)| *k == key && *r == radiance && *m == material && *f == media);
                if !same {
                    emitters += &flush(&mut out, &mut tri_run);
                    tri_run = Some((key, radiance, material, media, PlyMesh::new(false)));
                }
                if let Some((_, _, _, _, mesh)) = tri_run.as_mut() {
                    mesh.push([t.v0, t.v1, t.v2].map(at), [t.normal; 3]);
                }
            }
            Light::Area(AreaLight { surface: Emitting::Disk(d), radiance, material, .. }) => {
                emitters += &flush(&mut out, &mut tri_run);
                let _ = write!(
                    emitters,
                    "    <shape type=\"disk\">\n        {}\n{}{}        <emitter type=\"area\"><rgb name=\"radiance\" value=\"{}\"/></emitter>\n    </shape>\n",
                    disk_transform(at(d.center), d.normal, d.radius * s),
                    bsdf_ref(*material),
                    interface_refs(media),
                    rgb(*radiance)
                );
            }
            // The map as a file beside the scene: the texels as they light
            // it (scaled), in float32, so read back it is the same to the bit.
            Light::Envmap(env) => {
                emitters += &flush(&mut out, &mut tri_run);
                let (image, to_world) = env.map.image();
                let bytes = crate::output::exr_bytes(&image).map_err(|e| refuse(light_place(), e.to_string()))?;
                let name = format!("{}/envmap{:03}.exr", out.mesh_dir, out.meshes.len());
                out.meshes.push((name.clone(), bytes));
                let _ = write!(
                    emitters,
                    "    <emitter type=\"envmap\">\n        <string name=\"filename\" value=\"{name}\"/>\n        {}\n    </emitter>\n",
                    matrix(&Affine3A::from_mat3(to_world))
                );
            }
            // Every other light describes itself, moved as the scene is.
            other => {
                emitters += &flush(&mut out, &mut tri_run);
                let mut moved = other.clone();
                moved.moved(placement.origin, s);
                emitters += &emitter(&moved.mitsuba().map_err(|m| refuse(light_place(), m))?);
            }
        }
    }
    emitters += &flush(&mut out, &mut tri_run);

    let integrator = if out.media { "volpath" } else { "path" };
    let camera = match parts.media.camera {
        Some(m) => camera.replacen(
            "</sensor>",
            &format!("    <ref name=\"medium\" id=\"{}\"/>\n    </sensor>", super::mitsuba_medium::id(m)),
            1,
        ),
        None => camera,
    };
    let (w, h) = (parts.camera.width, parts.camera.height);
    let mut xml = String::new();
    let _ = write!(
        xml,
        "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<!-- Written by photonmap export. Parameters: spp, seed, width, height. \
         A point p of the scene is here (p - ({})) x {}. -->\n\
         <scene version=\"3.0.0\">\n    <default name=\"spp\" value=\"64\"/>\n    <default name=\"seed\" value=\"0\"/>\n\
         \x20   <default name=\"width\" value=\"{w}\"/>\n    <default name=\"height\" value=\"{h}\"/>\n\
         \x20   <integrator type=\"{integrator}\">\n        <integer name=\"max_depth\" value=\"-1\"/>\n    </integrator>\n\
         {camera}{bsdfs}{shapes}{emitters}</scene>\n",
        xyz(placement.origin),
        s
    );
    out.xml = xml;
    Ok(MitsubaScene { xml: out.xml, meshes: out.meshes, notes: out.notes })
}

struct Exporter<'a> {
    mesh_dir: &'a str,
    xml: String,
    meshes: Vec<(String, Vec<u8>)>,
    notes: Vec<String>,
    media: bool,
    placement: Placement,
}

impl Exporter<'_> {
    /// A `ply` shape of `mesh` with the given references and emitter.
    fn mesh(&mut self, mesh: PlyMesh, refs: &str, emitter: &str) -> String {
        if mesh.is_empty() {
            return String::new();
        }
        let name = format!("{}/{:03}.ply", self.mesh_dir, self.meshes.len());
        let face_normals =
            if mesh.is_smooth() { "" } else { "        <boolean name=\"face_normals\" value=\"true\"/>\n" };
        self.meshes.push((name.clone(), mesh.to_bytes()));
        format!("    <shape type=\"ply\">\n        <string name=\"filename\" value=\"{name}\"/>\n{face_normals}{refs}{emitter}    </shape>\n")
    }

    /// An ellipsoid: a `sphere` when its transform scales evenly (with
    /// its `to_world` where it also turns or mirrors, so that its texture
    /// coordinates are the same), else a tessellation with the
    /// ellipsoid's own normals at its vertices, and, in a scene that reads
    /// textures (`uv`), the sphere's coordinates there.
    fn ellipsoid(&mut self, e: &Ellipsoid, refs: &str, uv: bool) -> String {
        let p = self.placement;
        let m = Affine3A::from_scale(Vec3::splat(p.scale)) * Affine3A::from_translation(-p.origin) * e.to_world();
        let cols = [m.matrix3.x_axis, m.matrix3.y_axis, m.matrix3.z_axis];
        let s = cols[0].length();
        let even = cols.iter().all(|c| (c.length() - s).abs() <= 1e-5 * s)
            && (cols[0].dot(cols[1]).abs() + cols[1].dot(cols[2]).abs() + cols[0].dot(cols[2]).abs()) <= 1e-5 * s * s;
        let flip = if e.is_flipped() { "        <boolean name=\"flip_normals\" value=\"true\"/>\n" } else { "" };
        let plain =
            m.matrix3 == glam::Mat3A::from_diagonal(Vec3::splat(m.matrix3.x_axis.x)) && m.matrix3.x_axis.x > 0.0;
        if even && plain {
            return format!(
                "    <shape type=\"sphere\">\n        <point name=\"center\" value=\"{}\"/>\n        <float name=\"radius\" value=\"{}\"/>\n{flip}{refs}    </shape>\n",
                xyz(Vec3::from(m.translation)),
                s
            );
        }
        if even {
            return format!("    <shape type=\"sphere\">\n        {}\n{flip}{refs}    </shape>\n", matrix(&m));
        }
        let normal_map = m.matrix3.inverse().transpose();
        let sphere = icosphere(5);
        let mut mesh = if uv { PlyMesh::textured(true) } else { PlyMesh::new(true) };
        let sign = if e.is_flipped() { -1.0 } else { 1.0 };
        for f in &sphere.faces {
            // Flipped: wound the other way, normals inwards.
            let f = if e.is_flipped() { [f[0], f[2], f[1]] } else { *f };
            let p = f.map(|i| m.transform_point3(sphere.positions[i as usize]));
            let n =
                f.map(|i| sign * Vec3::from(normal_map * glam::Vec3A::from(sphere.normals[i as usize])).normalize());
            mesh.push_uv(p, n, sphere_uvs(f.map(|i| sphere.positions[i as usize])));
        }
        self.notes.push(format!(
            "an ellipsoid (unevenly scaled sphere) is written as a {}-triangle mesh with its exact normals at the \
             vertices: Mitsuba 3's sphere takes no uneven scale",
            sphere.faces.len()
        ));
        self.mesh(mesh, refs, "")
    }
}

/// Mitsuba's sphere coordinates (as `texture::SurfaceUv::Sphere`) at a
/// triangle's corners on the unit sphere, interpolated across it: a
/// triangle across the seam at u = 0 takes its corners' u past 1, a corner
/// at a pole (where u is undefined) the mean u of the other two.
fn sphere_uvs(corners: [Vec3; 3]) -> [Vec2; 3] {
    use std::f32::consts::PI;
    let mut uv = corners.map(|p| {
        let u = p.y.atan2(p.x) / (2.0 * PI);
        Vec2::new(if u < 0.0 { u + 1.0 } else { u }, p.z.clamp(-1.0, 1.0).acos() / PI)
    });
    let pole = corners.map(|p| p.x.abs() < 1e-6 && p.y.abs() < 1e-6);
    let us = || (0..3).filter(|&k| !pole[k]).map(|k| uv[k].x);
    if us().fold(f32::MIN, f32::max) - us().fold(f32::MAX, f32::min) > 0.5 {
        for k in 0..3 {
            if !pole[k] && uv[k].x < 0.5 {
                uv[k].x += 1.0;
            }
        }
    }
    for k in 0..3 {
        if pole[k] {
            let others: Vec<f32> = (0..3).filter(|&j| !pole[j]).map(|j| uv[j].x).collect();
            uv[k].x = others.iter().sum::<f32>() / others.len().max(1) as f32;
        }
    }
    uv
}

/// References to material `m`'s BSDF and, for absorbing glass, its
/// medium; or the media the shape bounds (not both: a body of absorbing
/// glass is its own medium).
fn material_refs(parts: &SceneParts, m: u32, media: Option<crate::medium::Interface>) -> Result<String, String> {
    let mut s = format!("        <ref id=\"material{m}\"/>\n");
    if parts.materials[m as usize].absorption().is_some() {
        if media.is_some() {
            return Err("absorbing glass that also bounds a medium has no equivalent in Mitsuba 3 (a shape has one \
                        interior); give the medium the absorption instead"
                .to_string());
        }
        s += &format!("        <ref name=\"interior\" id=\"medium{m}\"/>\n");
    }
    Ok(s + &interface_refs(media))
}

fn bsdf_ref(material: Option<u32>) -> String {
    match material {
        Some(m) => format!("        <ref id=\"material{m}\"/>\n"),
        None => "        <ref id=\"black\"/>\n".to_string(),
    }
}

/// A material's BSDF, or why it has none.
fn bsdf(m: &Material, id: &str) -> Result<String, String> {
    Ok(match *m {
        Material::Lambertian { rho } => format!(
            "    <bsdf type=\"twosided\" id=\"{id}\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"{}\"/></bsdf></bsdf>\n",
            rgb(rho)
        ),
        Material::Mirror { reflectance } => format!(
            "    <bsdf type=\"twosided\" id=\"{id}\"><bsdf type=\"conductor\"><string name=\"material\" value=\"none\"/><rgb name=\"specular_reflectance\" value=\"{}\"/></bsdf></bsdf>\n",
            rgb(reflectance)
        ),
        Material::Glass { ior, .. } => format!(
            "    <bsdf type=\"dielectric\" id=\"{id}\"><float name=\"int_ior\" value=\"{ior}\"/><float name=\"ext_ior\" value=\"1\"/></bsdf>\n"
        ),
        Material::Phong(_) => {
            return Err("the Phong material has no equivalent in Mitsuba 3 (its glossy and mirror lobes are \
                        photonmap's reading of the course's formula); use lambertian, mirror or glass"
                .into())
        }
        Material::Emitter => format!("    <bsdf type=\"diffuse\" id=\"{id}\"><rgb name=\"reflectance\" value=\"0, 0, 0\"/></bsdf>\n"),
        // The materials with Mitsuba's own parameters; a material added to
        // photonmap renders before the export knows it: until an arm says
        // what it is in Mitsuba, exporting a scene that uses it is refused
        // with its place.
        _ => match super::mitsuba_bsdf::bsdf(m, id) {
            Some(xml) => xml,
            None => return Err("this material has no equivalent in the Mitsuba export yet".into()),
        },
    })
}

/// The transform taking Mitsuba's unit disk (normal +z) to a disk.
fn disk_transform(center: Vec3, normal: Vec3, radius: f32) -> String {
    matrix(&crate::shape::Disk { center, normal, radius }.to_world())
}

pub(super) fn matrix(m: &Affine3A) -> String {
    let c = [m.matrix3.x_axis, m.matrix3.y_axis, m.matrix3.z_axis, m.translation];
    let rows: Vec<String> =
        (0..3).map(|r| (0..4).map(|k| format!("{}", c[k][r])).collect::<Vec<_>>().join(" ")).collect();
    format!("<transform name=\"to_world\"><matrix value=\"{} 0 0 0 1\"/></transform>", rows.join(" "))
}

pub(super) fn xyz(v: Vec3) -> String {
    format!("{}, {}, {}", v.x, v.y, v.z)
}

fn rgb(c: Color) -> String {
    xyz(c)
}

/// A light's `<emitter>` element.
fn emitter(e: &MitsubaEmitter) -> String {
    let mut xml = format!("    <emitter type=\"{}\">\n", e.plugin);
    for (name, param) in &e.params {
        let _ = match *param {
            MitsubaParam::Rgb(c) => writeln!(xml, "        <rgb name=\"{name}\" value=\"{}\"/>", rgb(c)),
            MitsubaParam::Point(p) => writeln!(xml, "        <point name=\"{name}\" value=\"{}\"/>", xyz(p)),
            MitsubaParam::Vector(v) => writeln!(xml, "        <vector name=\"{name}\" value=\"{}\"/>", xyz(v)),
            MitsubaParam::Float(x) => writeln!(xml, "        <float name=\"{name}\" value=\"{x}\"/>"),
            MitsubaParam::LookAt { origin, target, up } => writeln!(
                xml,
                "        <transform name=\"{name}\"><lookat origin=\"{}\" target=\"{}\" up=\"{}\"/></transform>",
                xyz(origin),
                xyz(target),
                xyz(up)
            ),
        };
    }
    xml + "    </emitter>\n"
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::PointLight;
    use crate::scene::{Eye, Prim, Scene};
    use crate::shape::Triangle;

    fn triangle(v: [Vec3; 3]) -> Triangle {
        Triangle::new(v[0], v[1], v[2])
    }

    fn export(parts: &SceneParts) -> MitsubaScene {
        to_mitsuba(parts, None, "m", Placement::at_eye(&parts.camera))
            .unwrap_or_else(|r| panic!("{}", r.describe(None)))
    }

    /// The default room: every feature of it has its element.
    #[test]
    fn the_default_room_exports_every_part() {
        let parts = Scene::tncg15_parts(Eye::One);
        let s = export(&parts);
        let x = &s.xml;
        for want in [
            "type=\"perspective\"",
            "name=\"fov\" value=\"53.13",
            // Positions relative to the eye at (-2, 0, 0): the glass
            // sphere's centre (9.5, -2, -3) is written 2 further along x.
            "<lookat origin=\"0, 0, 0\"",
            "name=\"center\" value=\"11.5, -2, -3\"",
            "type=\"twosided\"",
            "type=\"dielectric\"",
            "name=\"int_ior\" value=\"1.5\"",
            "type=\"conductor\"",
            "name=\"specular_reflectance\" value=\"0.95, 0.95, 0.95\"",
            "type=\"sphere\"",
            "name=\"radius\" value=\"1.5\"",
            "type=\"disk\"",
            "type=\"area\"",
            "name=\"radiance\" value=\"10, 10, 10\"",
            "type=\"ply\"",
            "face_normals",
            "<integrator type=\"path\">",
        ] {
            assert!(x.contains(want), "missing {want}:\n{x}");
        }
        assert!(!x.contains("principal_point_offset"), "the room's eye is centred");
        // The room is one object of seven materials, the tetrahedron one more.
        assert_eq!(s.meshes.len(), 8);
        let faces: usize = s
            .meshes
            .iter()
            .map(|(_, b)| {
                let t = String::from_utf8_lossy(b);
                t.split("element face ").nth(1).unwrap().split('\n').next().unwrap().parse::<usize>().unwrap()
            })
            .sum();
        assert_eq!(faces, 28);
    }

    fn parts_with(prims: Vec<Prim>, materials: Vec<Material>, lights: Vec<Light>) -> SceneParts {
        SceneParts {
            prims,
            shading_normals: Vec::new(),
            materials,
            lights,
            ambient: Color::ZERO,
            camera: Scene::tncg15_parts(Eye::One).camera,
            one_sided: Vec::new(),
            paths: crate::scene::PathLimits::default(),
            texturing: Default::default(),
            media: Default::default(),
        }
    }

    #[test]
    fn lights_absorption_ellipsoids_and_smooth_meshes() {
        let t = triangle([Vec3::ZERO, Vec3::X, Vec3::Y]);
        let mut smooth = t;
        smooth.shading = 0;
        let e = Ellipsoid::new(Affine3A::from_scale(Vec3::new(2.0, 1.0, 1.0))).unwrap();
        let round = Ellipsoid::new(Affine3A::from_scale(Vec3::splat(3.0))).unwrap();
        let mut parts = parts_with(
            vec![
                Prim { shape: Shape::Triangle(smooth), material: 0, object: 0 },
                Prim { shape: Shape::Ellipsoid(e), material: 0, object: 1 },
                Prim { shape: Shape::Ellipsoid(round), material: 0, object: 2 },
            ],
            vec![Material::Glass { ior: 1.33, absorption: Color::new(0.1, 0.2, 0.3) }],
            vec![
                Light::Directional(crate::light::Directional::new(Vec3::new(0.0, 0.0, -1.0), Color::splat(2.0))),
                Light::Point(PointLight {
                    position: Vec3::ONE,
                    intensity: Color::splat(5.0),
                    falloff: 2.0,
                    dead_distance: 0.0,
                }),
                AreaLight::unplaced(Emitting::Triangle(t), Color::splat(3.0), None),
            ],
        );
        parts.shading_normals.push([Vec3::Z, Vec3::Z, Vec3::new(0.0, 0.6, 0.8)]);
        let s = export(&parts);
        let x = &s.xml;
        for want in [
            "<integrator type=\"volpath\">",
            "type=\"homogeneous\"",
            "name=\"sigma_t\" value=\"0.1, 0.2, 0.3\"",
            "<ref name=\"interior\"",
            "type=\"directional\"",
            "name=\"irradiance\" value=\"2, 2, 2\"",
            "type=\"point\"",
            "name=\"intensity\" value=\"5, 5, 5\"",
            "<ref id=\"black\"/>",
        ] {
            assert!(x.contains(want), "missing {want}:\n{x}");
        }
        // The evenly scaled one is a sphere of radius 3.
        let radius: f32 =
            x.split("name=\"radius\" value=\"").nth(1).unwrap().split('"').next().unwrap().parse().unwrap();
        assert!((radius - 3.0).abs() < 1e-5, "{radius}");
        assert_eq!(s.notes.len(), 1, "{:?}", s.notes);
        assert!(s
            .meshes
            .iter()
            .any(|(_, b)| String::from_utf8_lossy(&b[..200.min(b.len())]).contains("property float nx")));
    }

    #[test]
    fn what_has_no_equivalent_is_refused() {
        let t = triangle([Vec3::ZERO, Vec3::X, Vec3::Y]);
        let phong = Material::Phong(crate::material::Phong {
            color: Color::ONE,
            ambient: 0.0,
            diffuse: 0.5,
            specular: 0.0,
            metalness: 0.0,
            shininess: 1.0,
            mirror: 0.0,
        });
        let parts = parts_with(vec![Prim { shape: Shape::Triangle(t), material: 0, object: 0 }], vec![phong], vec![]);
        let r = to_mitsuba(&parts, None, "m", Placement::at_eye(&parts.camera)).err().expect("refused");
        assert!(r.message.contains("Phong"));
        let falloff =
            Light::Point(PointLight { position: Vec3::ONE, intensity: Color::ONE, falloff: 1.0, dead_distance: 0.0 });
        let parts = parts_with(vec![], vec![], vec![falloff]);
        assert!(to_mitsuba(&parts, None, "m", Placement::at_eye(&parts.camera))
            .err()
            .expect("refused")
            .message
            .contains("1/d^2"));
        // Non-square pixels.
        let mut parts = parts_with(vec![], vec![], vec![]);
        parts.camera = parts.camera.with_resolution(400, 200);
        assert!(to_mitsuba(&parts, None, "m", Placement::at_eye(&parts.camera))
            .err()
            .expect("refused")
            .message
            .contains("square"));
    }

    /// A placement moves and scales every length, and what depends on
    /// lengths with them: the image stays the same.
    #[test]
    fn a_placement_moves_and_scales_every_length() {
        let ball = crate::shape::Sphere { center: Vec3::new(3.0, 1.0, 1.0), radius: 0.5 };
        let parts = parts_with(
            vec![Prim { shape: Shape::Sphere(ball), material: 0, object: 0 }],
            vec![Material::Glass { ior: 1.5, absorption: Color::splat(0.4) }],
            vec![Light::Point(PointLight {
                position: Vec3::new(1.0, 1.0, 3.0),
                intensity: Color::splat(5.0),
                falloff: 2.0,
                dead_distance: 0.0,
            })],
        );
        let placement = Placement::new(Vec3::new(3.0, 1.0, 1.0), 100.0).unwrap();
        let x = to_mitsuba(&parts, None, "m", placement).unwrap_or_else(|r| panic!("{}", r.describe(None))).xml;
        for want in [
            "name=\"center\" value=\"0, 0, 0\"",
            "name=\"radius\" value=\"50\"",
            "name=\"position\" value=\"-200, 0, 200\"",
            "name=\"intensity\" value=\"50000, 50000, 50000\"",
            "name=\"sigma_t\" value=\"0.004, 0.004, 0.004\"",
            // The room's eye, (-2, 0, 0).
            "<lookat origin=\"-500, -100, -100\"",
        ] {
            assert!(x.contains(want), "missing {want}:\n{x}");
        }
        assert!(Placement::new(Vec3::ZERO, 0.0).is_err());
        assert!(Placement::new(Vec3::new(f32::NAN, 0.0, 0.0), 1.0).is_err());
    }

    /// An eye off the plane's centre is kept by the principal point's offset.
    #[test]
    fn an_off_centre_eye_is_an_offset_principal_point() {
        let mut parts = parts_with(vec![], vec![], vec![]);
        let c = [
            Vec3::new(0.0, -1.0, -1.0),
            Vec3::new(0.0, 1.0, -1.0),
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::new(0.0, -1.0, 1.0),
        ];
        // The eye 0.5 to the right (-y) and 0.25 up of the centre.
        parts.camera = Camera::from_corners(Vec3::new(-2.0, -0.5, 0.25), c, 100, 100);
        let x = export(&parts).xml;
        assert!(x.contains("principal_point_offset_x\" value=\"-0.25\""), "{x}");
        assert!(x.contains("principal_point_offset_y\" value=\"0.125\""), "{x}");
    }
}
