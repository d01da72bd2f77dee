//! A scene's participating media for Mitsuba 3: each medium as its
//! `homogeneous` or `heterogeneous` plugin (the same parameters the
//! front-end reads, src/scene/mitsuba/media.rs), grids written as `.vol`
//! files beside the meshes, and the references a shape (`interior`,
//! `exterior`) or the sensor (`medium`) makes to them. Lengths follow the
//! export's [`Placement`]: volumes are placed by it, and extinction, per
//! unit length, is divided by its scale.

use super::mitsuba::{matrix, xyz, Placement};
use crate::medium::{Interface, Medium, Phase, Volume};
use glam::{Affine3A, Vec3};
use std::fmt::Write;

/// The `<medium>` definitions of `media` (ids `volume_medium{i}`), and the
/// `.vol` files they name (under `dir`).
pub(super) fn media(media: &[Medium], dir: &str, placement: Placement) -> (String, Vec<(String, Vec<u8>)>) {
    let mut xml = String::new();
    let mut files = Vec::new();
    let place = Affine3A::from_scale(Vec3::splat(placement.scale)) * Affine3A::from_translation(-placement.origin);
    for (i, m) in media.iter().enumerate() {
        let kind = if m.is_homogeneous() { "homogeneous" } else { "heterogeneous" };
        let _ = writeln!(xml, "    <medium type=\"{kind}\" id=\"{}\">", id(i as u32));
        let mut volume = |name: &str, v: &Volume, bounded: bool| {
            match v {
            Volume::Constant { value, .. } if !bounded => {
                format!("        <rgb name=\"{name}\" value=\"{}\"/>\n", xyz(*value))
            }
            Volume::Constant { value, to_world } => format!(
                "        <volume type=\"constvolume\" name=\"{name}\">\n            <rgb name=\"value\" value=\"{}\"/>\n            {}\n        </volume>\n",
                xyz(*value),
                matrix(&(place * *to_world))
            ),
            Volume::Grid(g) => {
                let file = format!("{dir}/medium{i}_{name}.vol");
                files.push((file.clone(), g.data.to_bytes()));
                format!(
                    "        <volume type=\"gridvolume\" name=\"{name}\">\n            <string name=\"filename\" value=\"{file}\"/>\n            <boolean name=\"use_grid_bbox\" value=\"{}\"/>\n            <string name=\"filter_type\" value=\"{}\"/>\n            <string name=\"wrap_mode\" value=\"{}\"/>\n            {}\n        </volume>\n",
                    g.use_grid_bbox,
                    g.filter.name(),
                    g.wrap.name(),
                    matrix(&(place * g.to_world))
                )
            }
        }
        };
        // A homogeneous medium's extinction is a colour; a heterogeneous
        // one's volume bounds its density, so its placement is written.
        xml += &volume("sigma_t", &m.sigma_t, !m.is_homogeneous());
        xml += &volume("albedo", &m.albedo, false);
        let _ = writeln!(xml, "        <float name=\"scale\" value=\"{}\"/>", m.scale / placement.scale);
        if !m.sample_emitters {
            xml += "        <boolean name=\"sample_emitters\" value=\"false\"/>\n";
        }
        xml += &match m.phase {
            Phase::Isotropic => "        <phase type=\"isotropic\"/>\n".to_string(),
            Phase::HenyeyGreenstein { g } => {
                format!("        <phase type=\"hg\"><float name=\"g\" value=\"{g}\"/></phase>\n")
            }
        };
        xml += "    </medium>\n";
    }
    (xml, files)
}

/// A medium's id in the exported scene.
pub(super) fn id(medium: u32) -> String {
    format!("volume_medium{medium}")
}

/// A shape's references to the media on either side of it.
pub(super) fn interface_refs(interface: Option<Interface>) -> String {
    let Some(i) = interface else { return String::new() };
    let mut s = String::new();
    for (name, m) in [("interior", i.interior), ("exterior", i.exterior)] {
        if let Some(m) = m {
            let _ = writeln!(s, "        <ref name=\"{name}\" id=\"{}\"/>", id(m));
        }
    }
    s
}
