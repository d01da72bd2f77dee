//! The TOML scene file's Mitsuba materials and textures: every type the
//! Mitsuba front-end reads, written in TOML, renders to the bit the same
//! image as the scene `photonmap export --mitsuba` makes of it read back,
//! and as the same scene written by hand in Mitsuba's XML; mistakes are
//! refused at their file, line and field. Each test writes its own small
//! images.

mod common;

use common::{render_quiet, scratch_dir};
use photonmap::export::mitsuba::{to_mitsuba, Placement};
use photonmap::film::Film;
use photonmap::math::Color;
use photonmap::scene::mitsuba::{load, Options};
use photonmap::scene::Scene;
use photonmap::settings::{Method, Settings};
use std::path::Path;

/// A 4x4 sRGB PNG of distinct colours, a 3x2 EXR of linear ones, an OBJ
/// quad with texture coordinates.
fn write_images(dir: &Path) {
    let obj = "v -3 0 1.5\nv 3 0 1.5\nv 3 3 1.5\nv -3 3 1.5\nvt 0 0\nvt 2 0\nvt 2 1\nvt 0 1\nf 1/1 4/4 3/3 2/2\n";
    std::fs::write(dir.join("quad.obj"), obj).unwrap();
    let rgb: Vec<u8> = (0..16u32).flat_map(|i| [i * 15, 255 - i * 13, (i * 37) % 256].map(|v| v as u8)).collect();
    photonmap::output::write_rgb8_image(&dir.join("tex.png"), 4, 4, rgb).unwrap();
    let film = Film {
        width: 3,
        height: 2,
        pixels: (0..6).map(|i| Color::new(0.1 + 0.1 * i as f32, 0.8 - 0.1 * i as f32, 0.3)).collect(),
    };
    photonmap::output::write(&dir.join("tex.exr"), &film, Default::default(), 1.0).unwrap();
}

const CAMERA: &str = r#"
[camera]
eye = [0, 1.5, -6]
target = [0, 0.8, 0]
up = [0, 1, 0]
vfov = 50
width = 32
height = 24
"#;

/// Every material type and texture the TOML reader has, on spheres, a
/// disk and a quad; nested by name and inline.
const EVERY: &str = r#"
[textures.checks]
type = "checkerboard"
color0 = [0.8, 0.2, 0.1]
color1 = 0.3
to_uv = [{ scale = [6, 3, 1] }]

[textures.photo]
type = "bitmap"
filename = "tex.png"

[textures.linear]
type = "bitmap"
filename = "tex.exr"
filter_type = "nearest"
wrap_mode = "clamp"

[materials.floor]
type = "diffuse"
reflectance = "checks"

[materials.white]
type = "lambertian"
rho = [0.7, 0.7, 0.7]

[materials.grey]
type = "lambertian"
rho = [0.2, 0.3, 0.4]

[materials.metal]
type = "conductor"
eta = [0.2, 0.4, 1.4]
k = [3.9, 2.4, 1.6]
specular_reflectance = "photo"

[materials.brushed]
type = "roughconductor"
distribution = "ggx"
alpha_u = { type = "bitmap", filename = "tex.png", raw = true }
alpha_v = 0.3

[materials.frosted]
type = "roughdielectric"
alpha = 0.15
int_ior = 1.4
specular_transmittance = "checks"

[materials.pane]
type = "thindielectric"
int_ior = 1.6

[materials.plastic]
type = "plastic"
diffuse_reflectance = "linear"
nonlinear = true

[materials.varnish]
type = "roughplastic"
distribution = "ggx"
alpha = 0.2
diffuse_reflectance = { type = "checkerboard", to_uv = [{ rotate = { axis = [0, 0, 1], degrees = 30 } }] }

[materials.disney]
type = "principled"
base_color = "photo"
metallic = 0.3
roughness = "checks"
clearcoat = 0.5
specular = 0.6

[materials.leaf]
type = "principledthin"
base_color = "checks"
eta = 1.4
diff_trans = 0.5

[materials.coated]
type = "twosided"
material = "disney"

[materials.mix]
type = "blendbsdf"
weight = "photo"
materials = ["plastic", { type = "roughconductor", alpha = 0.05 }]

[materials.two_diffuse]
type = "blendbsdf"
weight = 0.25
materials = ["white", "grey"]

[materials.holes]
type = "mask"
opacity = "checks"
material = "white"

[materials.holey_metal]
type = "mask"
opacity = 0.6
material = "brushed"

[materials.bumpy]
type = "bumpmap"
texture = "photo"
scale = 0.5
material = "varnish"

[materials.normals]
type = "normalmap"
normalmap = { type = "bitmap", filename = "tex.png", raw = true }
material = { type = "diffuse", reflectance = [0.5, 0.6, 0.7] }

[[shapes]]
type = "quad"
vertices = [[-6, 0, -6], [-6, 0, 6], [6, 0, 6], [6, 0, -6]]
material = "floor"

[[shapes]]
type = "mesh"
file = "quad.obj"
transform = [{ rotate = { axis = [0, 1, 0], degrees = 10 } }]
material = "varnish"

[[shapes]]
type = "disk"
center = [0, 2, 4]
normal = [0.2, 0, -1]
radius = 2
material = "bumpy"

[[lights]]
type = "disk"
center = [0, 5, -1]
normal = [0, -1, 0]
radius = 1
radiance = [12, 12, 12]
"#;

/// The spheres of [`EVERY`]: one per material, in a grid.
fn spheres() -> String {
    let names = [
        "metal",
        "brushed",
        "frosted",
        "pane",
        "plastic",
        "varnish",
        "disney",
        "leaf",
        "coated",
        "mix",
        "two_diffuse",
        "holes",
        "holey_metal",
        "normals",
        "white",
    ];
    names
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let (x, y) = ((i % 5) as f32 * 0.9 - 1.8, (i / 5) as f32 * 0.9 + 0.4);
            format!("\n[[shapes]]\ntype = \"sphere\"\ncenter = [{x}, {y}, 0]\nradius = 0.4\nmaterial = \"{m}\"\n")
        })
        .collect()
}

fn settings(scene: &Scene) -> Settings {
    Settings {
        method: Method::Photon,
        photons: 20_000,
        caustic_photons: 20_000,
        spp: 4,
        width: scene.camera.width,
        height: scene.camera.height,
        ..Settings::default()
    }
}

/// The pixels' bits that differ between two renders.
fn differing(a: &Film, b: &Film) -> usize {
    assert_eq!((a.width, a.height), (b.width, b.height));
    a.pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| p.to_array().map(f32::to_bits) != q.to_array().map(f32::to_bits))
        .count()
}

fn read_xml(path: &Path) -> photonmap::scene::SceneParts {
    load(path, &Options { defines: Vec::new(), substitute: false }).unwrap_or_else(|e| panic!("{e}")).file.parts
}

/// Every material and texture type, from TOML and from its Mitsuba
/// export read back: the same image to the bit.
#[test]
fn every_material_and_texture_survives_the_export_and_the_import() {
    let dir = scratch_dir("toml_materials_roundtrip");
    write_images(&dir);
    let text = format!("{CAMERA}{EVERY}{}", spheres());
    let path = dir.join("every.toml");
    std::fs::write(&path, &text).unwrap();
    let file = photonmap::scene::file::load(&path).unwrap_or_else(|e| panic!("{e}"));
    assert!(file.parts.texturing.is_used(), "the scene reads textures");
    assert!(file.parts.one_sided.iter().any(|&b| b), "the principled material is one-sided");
    let exported =
        to_mitsuba(&file.parts, Some(&file.origins), "every-meshes", Placement::new(glam::Vec3::ZERO, 1.0).unwrap())
            .unwrap_or_else(|e| panic!("{}", e.describe(Some(&file.origins))));
    for kind in [
        "diffuse",
        "conductor",
        "roughconductor",
        "roughdielectric",
        "thindielectric",
        "\"plastic\"",
        "roughplastic",
        "\"principled\"",
        "principledthin",
        "blendbsdf",
        "mask",
        "bumpmap",
        "normalmap",
        "twosided",
        "\"bitmap\"",
        "checkerboard",
    ] {
        assert!(exported.xml.contains(kind), "the export writes {kind}");
    }
    // The two images are copied beside the meshes, each once.
    let images: Vec<&str> = exported.meshes.iter().map(|(n, _)| n.as_str()).filter(|n| n.contains("texture")).collect();
    assert_eq!(images, ["every-meshes/texture000.png", "every-meshes/texture001.exr"]);
    // The OBJ's texture coordinates go into its PLY (and only into its).
    let with_uv =
        exported.meshes.iter().filter(|(_, b)| String::from_utf8_lossy(b).contains("property float u\n")).count();
    assert_eq!(with_uv, 1);
    std::fs::create_dir_all(dir.join("every-meshes")).unwrap();
    for (name, bytes) in &exported.meshes {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    std::fs::write(dir.join("every.xml"), &exported.xml).unwrap();
    let back = read_xml(&dir.join("every.xml"));
    let mut b = back;
    b.camera = file.parts.camera;
    let (a, b) = (Scene::from_parts(file.parts), Scene::from_parts(b));
    let (fa, fb) = (render_quiet(&a, &settings(&a)), render_quiet(&b, &settings(&b)));
    assert!(fa.mean().abs() > 1e-3, "the image is not black");
    assert_eq!(differing(&fa, &fb), 0, "pixels differ between the TOML scene and its export read back");
}

/// A TOML scene and the same scene written by hand in Mitsuba's XML give
/// the same image.
#[test]
fn a_toml_scene_renders_as_its_hand_written_xml() {
    let dir = scratch_dir("toml_materials_xml");
    write_images(&dir);
    let toml = format!(
        r#"{CAMERA}
[textures.photo]
type = "bitmap"
filename = "tex.png"

[materials.disney]
type = "principled"
base_color = "photo"
metallic = 0.3
roughness = 0.4

[materials.mix]
type = "blendbsdf"
weight = 0.3
materials = ["shiny", {{ type = "diffuse", reflectance = {{ type = "checkerboard", to_uv = [{{ scale = [4, 4, 1] }}] }} }}]

[materials.shiny]
type = "roughconductor"
material = "Cu"
alpha = 0.2

[materials.coat]
type = "plastic"
int_ior = "water"

[materials.floor]
type = "bumpmap"
texture = "photo"
scale = 0.3
material = {{ type = "diffuse", reflectance = 0.6 }}

[[shapes]]
type = "sphere"
center = [-0.6, 0.8, 0]
radius = 0.5
material = "disney"

[[shapes]]
type = "sphere"
center = [0.6, 0.8, 0]
radius = 0.5
material = "mix"

[[shapes]]
type = "sphere"
center = [0, -100, 0]
radius = 100
material = "floor"

[[shapes]]
type = "mesh"
file = "quad.obj"
material = "coat"

[[lights]]
type = "point"
position = [0, 4, -2]
color = [20, 20, 20]
"#
    );
    let xml = r#"<scene version="3.0.0">
    <sensor type="perspective"><float name="fov" value="50"/>
        <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/></film>
    </sensor>
    <bsdf type="principled" id="disney">
        <texture type="bitmap" name="base_color"><string name="filename" value="tex.png"/></texture>
        <float name="metallic" value="0.3"/>
        <float name="roughness" value="0.4"/>
    </bsdf>
    <bsdf type="twosided" id="shiny"><bsdf type="roughconductor">
        <string name="material" value="Cu"/><float name="alpha" value="0.2"/>
    </bsdf></bsdf>
    <bsdf type="twosided" id="coat"><bsdf type="plastic"><string name="int_ior" value="water"/></bsdf></bsdf>
    <bsdf type="blendbsdf" id="mix">
        <float name="weight" value="0.3"/>
        <ref id="shiny"/>
        <bsdf type="twosided"><bsdf type="diffuse">
            <texture type="checkerboard" name="reflectance">
                <transform name="to_uv"><scale x="4" y="4"/></transform>
            </texture>
        </bsdf></bsdf>
    </bsdf>
    <shape type="sphere"><point name="center" value="-0.6, 0.8, 0"/><float name="radius" value="0.5"/><ref id="disney"/></shape>
    <shape type="sphere"><point name="center" value="0.6, 0.8, 0"/><float name="radius" value="0.5"/><ref id="mix"/></shape>
    <shape type="sphere">
        <point name="center" value="0, -100, 0"/><float name="radius" value="100"/>
        <bsdf type="bumpmap">
            <texture type="bitmap"><string name="filename" value="tex.png"/></texture>
            <float name="scale" value="0.3"/>
            <bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></bsdf>
        </bsdf>
    </shape>
    <shape type="obj"><string name="filename" value="quad.obj"/><ref id="coat"/></shape>
    <emitter type="point"><point name="position" value="0, 4, -2"/><rgb name="intensity" value="20"/></emitter>
</scene>
"#;
    std::fs::write(dir.join("scene.toml"), toml).unwrap();
    std::fs::write(dir.join("scene.xml"), xml).unwrap();
    let a = photonmap::scene::file::load(&dir.join("scene.toml")).unwrap_or_else(|e| panic!("{e}")).parts;
    let mut b = read_xml(&dir.join("scene.xml"));
    // The same view: the TOML's camera (Mitsuba's sensor is another's test).
    b.camera = a.camera;
    assert_eq!(format!("{:?}", a.lights), format!("{:?}", b.lights));
    let (a, b) = (Scene::from_parts(a), Scene::from_parts(b));
    let (fa, fb) = (render_quiet(&a, &settings(&a)), render_quiet(&b, &settings(&b)));
    assert!(fa.mean().abs() > 1e-3, "the image is not black");
    assert_eq!(differing(&fa, &fb), 0, "pixels differ between the TOML and the XML scene");
}

/// Each mistake is refused at its file, line and field.
#[test]
fn mistakes_in_materials_and_textures_are_located() {
    let dir = scratch_dir("toml_materials_errors");
    write_images(&dir);
    let light = "\n[[lights]]\ntype = \"point\"\nposition = [0, 4, 0]\ncolor = [1, 1, 1]\n";
    let sphere = "\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n";
    // (the material and texture tables, the line, the field, words of the message)
    let cases: [(&str, usize, &str, &str); 10] = [
        (
            "[materials.m]\ntype = \"roughdielectric\"\nint_ior = \"unobtainium\"\n",
            3,
            "materials.m.int_ior",
            "'unobtainium' is not a named index",
        ),
        (
            "[materials.m]\ntype = \"conductor\"\neta = 1.2\nmaterial = \"Au\"\n",
            4,
            "materials.m.material",
            "not both",
        ),
        ("[materials.m]\ntype = \"principled\"\ncolour = [1, 0, 0]\n", 3, "materials.m.colour", "unknown field `colour`"),
        ("[materials.m]\ntype = \"principled\"\nroughness = 1.5\n", 3, "materials.m.roughness", "must lie in [0, 1], got 1.5"),
        (
            "[materials.m]\ntype = \"diffuse\"\nreflectance = \"t\"\n\n[textures.t]\ntype = \"bitmap\"\nfilename = \"nope.png\"\n",
            7,
            "textures.t.filename",
            "nope.png",
        ),
        ("[materials.m]\ntype = \"diffuse\"\nreflectance = \"wood\"\n", 3, "materials.m.reflectance", "no texture named \"wood\""),
        (
            "[materials.m]\ntype = \"blendbsdf\"\nmaterials = [\"m\", \"m\"]\n",
            3,
            "materials.m.materials[0]",
            "contains itself",
        ),
        (
            "[materials.m]\ntype = \"mask\"\nmaterial = { type = \"diffuse\", shine = 1 }\n",
            3,
            "materials.m.material.shine",
            "unknown field `shine`",
        ),
        (
            "[materials.m]\ntype = \"diffuse\"\nreflectance = { type = \"checkerboard\", to_uv = 3 }\n",
            3,
            "materials.m.reflectance.to_uv",
            "invalid type",
        ),
        ("[materials.m]\ntype = \"conductor\"\nspecular_reflectance = \"t\"\n\n[textures.t]\ntype = \"wood\"\n", 6, "textures.t.type", "unknown texture type"),
    ];
    for (i, (tables, line, field, words)) in cases.iter().enumerate() {
        let path = dir.join(format!("bad{i}.toml"));
        std::fs::write(&path, format!("{CAMERA}{light}{sphere}\n{tables}")).unwrap();
        let offset = format!("{CAMERA}{light}{sphere}\n").lines().count();
        let e = photonmap::scene::file::load(&path).err().unwrap_or_else(|| panic!("case {i} is accepted"));
        assert_eq!((e.line, e.field.as_str()), (offset + line, *field), "case {i}: {e}");
        assert!(e.message.contains(words), "case {i}: {e}");
        assert!(e.to_string().starts_with(&path.display().to_string()), "case {i}: {e}");
    }
}

/// `trace` refuses a material it cannot render, at its place, and writes
/// nothing.
#[test]
fn trace_refuses_the_materials_it_cannot_render() {
    let dir = scratch_dir("toml_materials_trace");
    write_images(&dir);
    let light = "\n[[lights]]\ntype = \"point\"\nposition = [0, 4, 0]\ncolor = [1, 1, 1]\n";
    let sphere = "\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n";
    for (i, material) in [
        "type = \"principled\"",
        "type = \"roughconductor\"",
        "type = \"diffuse\"\nreflectance = { type = \"checkerboard\" }",
        "type = \"bumpmap\"\ntexture = { type = \"bitmap\", filename = \"tex.png\" }\nmaterial = { type = \"lambertian\", rho = [0.5, 0.5, 0.5] }",
    ]
    .iter()
    .enumerate()
    {
        let head = format!("{CAMERA}{light}{sphere}\n");
        let path = dir.join(format!("m{i}.toml"));
        std::fs::write(&path, format!("{head}[materials.m]\n{material}\n")).unwrap();
        let out = dir.join(format!("m{i}.png"));
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_trace")).args([&path, &out]).output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{material}: accepted");
        let place = format!("{}:{}:", path.display(), head.lines().count() + 2);
        assert!(stderr.contains(&place) && stderr.contains("materials.m"), "{material}: {stderr}");
        assert!(stderr.contains("Whitted tracer"), "{stderr}");
        assert!(!out.exists());
    }
    // What it reads, it still renders.
    let path = dir.join("fine.toml");
    std::fs::write(
        &path,
        format!("{CAMERA}{light}{sphere}\n[materials.m]\ntype = \"lambertian\"\nrho = [0.5, 0.5, 0.5]\n"),
    )
    .unwrap();
    let out = dir.join("fine.png");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_trace")).args([&path, &out]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// A textured ellipsoid reads its texture as Mitsuba's sphere under the
/// same transform, and keeps its coordinates through the export: exactly
/// where the transform scales evenly (written as a `sphere` with its
/// `to_world`, turned here), interpolated between the vertices of the
/// tessellation where it does not.
#[test]
fn a_textured_ellipsoid_keeps_its_coordinates_through_the_export() {
    let dir = scratch_dir("toml_materials_ellipsoid");
    let toml = r#"
[camera]
eye = [0, 0.5, -5]
target = [0, 0.5, 0]
up = [0, 1, 0]
vfov = 40
width = 64
height = 48

[materials.checks]
type = "diffuse"
reflectance = { type = "checkerboard", color0 = 0.9, color1 = 0.1, to_uv = [{ scale = [8, 4, 1] }] }

[[shapes]]
type = "ellipsoid"
transform = [{ rotate = { axis = [1, 1, 0], degrees = 40 } }, { scale = [0.8, 0.8, 0.8] }, { translate = [-0.9, 0.5, 0] }]
material = "checks"

[[shapes]]
type = "ellipsoid"
transform = [{ scale = [0.5, 0.9, 0.7] }, { rotate = { axis = [0, 1, 1], degrees = 25 } }, { translate = [0.9, 0.5, 0] }]
material = "checks"

[[lights]]
type = "point"
position = [0, 3, -4]
color = [30, 30, 30]
"#;
    let path = dir.join("ellipsoids.toml");
    std::fs::write(&path, toml).unwrap();
    let file = photonmap::scene::file::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let exported =
        to_mitsuba(&file.parts, Some(&file.origins), "ell-meshes", Placement::new(glam::Vec3::ZERO, 1.0).unwrap())
            .unwrap_or_else(|e| panic!("{}", e.describe(Some(&file.origins))));
    assert!(exported.xml.contains("<shape type=\"sphere\">") && exported.xml.contains("name=\"to_world\""));
    assert_eq!(exported.meshes.len(), 1, "the uneven one is a mesh");
    assert!(String::from_utf8_lossy(&exported.meshes[0].1).contains("property float u\n"), "with coordinates");
    std::fs::create_dir_all(dir.join("ell-meshes")).unwrap();
    for (name, bytes) in &exported.meshes {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    std::fs::write(dir.join("ellipsoids.xml"), &exported.xml).unwrap();
    let mut back = read_xml(&dir.join("ellipsoids.xml"));
    back.camera = file.parts.camera;
    let (a, b) = (Scene::from_parts(file.parts), Scene::from_parts(back));
    let s = Settings { gather_rays: 0, ..settings(&a) };
    let (fa, fb) = (render_quiet(&a, &s), render_quiet(&b, &s));
    // Pixels of each half (each ellipsoid) that differ by more than 10%
    // of the brighter check's image.
    let bright = fa.pixels.iter().map(|p| p.max_element()).fold(0.0f32, f32::max);
    let mut off = [0usize; 2];
    let mut checks = [(0usize, 0usize); 2];
    for (i, (p, q)) in fa.pixels.iter().zip(&fb.pixels).enumerate() {
        let half = usize::from(i as u32 % fa.width >= fa.width / 2);
        off[half] += usize::from((*p - *q).abs().max_element() > 0.1 * bright);
        let v = p.max_element();
        if v > 0.4 * bright {
            checks[half].0 += 1;
        } else if v > 0.01 * bright {
            checks[half].1 += 1;
        }
    }
    println!("differing {off:?}, light/dark {checks:?}");
    // Both ellipsoids show their checks (light and dark squares)...
    assert!(checks.iter().all(|&(l, d)| l > 20 && d > 20), "{checks:?}");
    // ... at the same places: exactly for the sphere (but a check's edge
    // through a pixel centre), within the tessellation's error otherwise.
    assert!(off[0] <= 3 && off[1] <= 30, "pixels differing per ellipsoid: {off:?}");
}

/// A PLY mesh's vertex and face colours as `mesh_attribute` textures:
/// the TOML scene renders as the same scene written in Mitsuba's XML, and
/// as its Mitsuba export read back, to the bit; a sphere of such a
/// material is refused by the export, and a name that is no attribute's
/// by the reader, each at its place.
#[test]
fn mesh_attributes_read_from_ply_as_in_mitsuba() {
    let dir = scratch_dir("toml_materials_attributes");
    // Two quads (four triangles): colours at the vertices, and per face.
    let vertices = "-1.5 0 0 1 0 0\n1.5 0 0 0 1 0\n1.5 2 0 0 0 1\n-1.5 2 0 1 1 0\n";
    let ply = format!(
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
         property float r\nproperty float g\nproperty float b\nelement face 2\nproperty list uchar int vertex_indices\n\
         end_header\n{vertices}3 0 1 2\n3 0 2 3\n"
    );
    std::fs::write(dir.join("vertex.ply"), ply).unwrap();
    let faces = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
         element face 2\nproperty list uchar int vertex_indices\nproperty float r\nproperty float g\nproperty float b\n\
         end_header\n-1 -1 0.5\n1 -1 0.5\n1 -0.2 0.5\n-1 -0.2 0.5\n3 0 1 2 0.9 0.2 0.1\n3 0 2 3 0.1 0.3 0.8\n";
    std::fs::write(dir.join("face.ply"), faces).unwrap();
    let toml = format!(
        r#"{CAMERA}
[textures.vc]
type = "mesh_attribute"
name = "vertex_color"

[materials.painted]
type = "diffuse"
reflectance = "vc"

[materials.tiles]
type = "diffuse"
reflectance = {{ type = "mesh_attribute", name = "face_color", scale = 0.8 }}

[[shapes]]
type = "mesh"
file = "vertex.ply"
face_normals = true
material = "painted"

[[shapes]]
type = "mesh"
file = "face.ply"
face_normals = true
material = "tiles"

[[lights]]
type = "point"
position = [0, 1, -3]
color = [10, 10, 10]
"#
    );
    let xml = r#"<scene version="3.0.0">
    <sensor type="perspective"><float name="fov" value="50"/>
        <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/></film>
    </sensor>
    <shape type="ply"><string name="filename" value="vertex.ply"/><boolean name="face_normals" value="true"/>
        <bsdf type="twosided"><bsdf type="diffuse">
            <texture type="mesh_attribute" name="reflectance"><string name="name" value="vertex_color"/></texture>
        </bsdf></bsdf>
    </shape>
    <shape type="ply"><string name="filename" value="face.ply"/><boolean name="face_normals" value="true"/>
        <bsdf type="twosided"><bsdf type="diffuse">
            <texture type="mesh_attribute" name="reflectance">
                <string name="name" value="face_color"/><float name="scale" value="0.8"/>
            </texture>
        </bsdf></bsdf>
    </shape>
    <emitter type="point"><point name="position" value="0, 1, -3"/><rgb name="intensity" value="10"/></emitter>
</scene>
"#;
    std::fs::write(dir.join("scene.toml"), &toml).unwrap();
    std::fs::write(dir.join("scene.xml"), xml).unwrap();
    let file = photonmap::scene::file::load(&dir.join("scene.toml")).unwrap_or_else(|e| panic!("{e}"));
    // The export writes each attribute into every mesh, as vertex
    // properties (the face colours repeated at their faces' corners).
    let exported =
        to_mitsuba(&file.parts, Some(&file.origins), "attr-meshes", Placement::new(glam::Vec3::ZERO, 1.0).unwrap())
            .unwrap_or_else(|e| panic!("{}", e.describe(Some(&file.origins))));
    assert_eq!(exported.xml.matches("type=\"mesh_attribute\"").count(), 2, "{}", exported.xml);
    assert_eq!(exported.meshes.len(), 2);
    for (_, bytes) in &exported.meshes {
        let text = String::from_utf8_lossy(bytes);
        assert_eq!(text.matches("property float attr").count(), 6, "{text}");
    }
    std::fs::create_dir_all(dir.join("attr-meshes")).unwrap();
    for (name, bytes) in &exported.meshes {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    std::fs::write(dir.join("exported.xml"), &exported.xml).unwrap();
    let a = file.parts;
    let mut b = read_xml(&dir.join("scene.xml"));
    b.camera = a.camera;
    let mut c = read_xml(&dir.join("exported.xml"));
    c.camera = a.camera;
    let (a, b, c) = (Scene::from_parts(a), Scene::from_parts(b), Scene::from_parts(c));
    let (fa, fb, fc) =
        (render_quiet(&a, &settings(&a)), render_quiet(&b, &settings(&b)), render_quiet(&c, &settings(&c)));
    // Colours vary over the image (the attributes are read, not zero).
    let hues = fa.pixels.iter().filter(|p| p.max_element() > 1e-3 && p.max_element() > 2.0 * p.min_element()).count();
    assert!(hues > 50, "{hues} coloured pixels");
    assert_eq!(differing(&fa, &fb), 0, "pixels differ between the TOML and the XML scene");
    assert_eq!(differing(&fa, &fc), 0, "pixels differ between the TOML scene and its export read back");

    // A sphere carries no attributes: one whose material reads them is
    // refused, at the shape (Mitsuba 3.9.1 refuses to render it).
    let sphere =
        format!("{toml}\n[[shapes]]\ntype = \"sphere\"\ncenter = [0, 3, 0]\nradius = 0.5\nmaterial = \"painted\"\n");
    std::fs::write(dir.join("sphere.toml"), &sphere).unwrap();
    let file = photonmap::scene::file::load(&dir.join("sphere.toml")).unwrap_or_else(|e| panic!("{e}"));
    let refused = to_mitsuba(&file.parts, Some(&file.origins), "m", Placement::new(glam::Vec3::ZERO, 1.0).unwrap())
        .err()
        .expect("refused")
        .describe(Some(&file.origins));
    assert!(refused.contains("mesh_attribute") && refused.contains("shapes[2]"), "{refused}");

    let bad = toml.replace("name = \"vertex_color\"", "name = \"color\"");
    std::fs::write(dir.join("bad.toml"), &bad).unwrap();
    let Err(e) = photonmap::scene::file::load(&dir.join("bad.toml")) else { panic!("a bad name is accepted") };
    assert_eq!(e.field, "textures.vc.name", "{e}");
    assert!(e.message.contains("must start with vertex_ or face_"), "{e}");
}
