//! The Mitsuba 3 BSDF of each material that takes Mitsuba's parameters
//! (`material::Conductor` and the rest): the same plugin, the same
//! parameter names. photonmap's surfaces reflect on both sides, so the
//! opaque ones are wrapped in `twosided`; dielectrics are two-sided
//! already.

use crate::material::{Distribution, Material, Microfacet};
use crate::math::Color;

fn rgb(name: &str, c: Color) -> String {
    format!("<rgb name=\"{name}\" value=\"{}, {}, {}\"/>", c.x, c.y, c.z)
}

fn float(name: &str, x: f32) -> String {
    format!("<float name=\"{name}\" value=\"{x}\"/>")
}

fn roughness(m: &Microfacet) -> String {
    let dist = match m.distribution {
        Distribution::Beckmann => "beckmann",
        Distribution::Ggx => "ggx",
    };
    let alpha = if m.alpha_u == m.alpha_v {
        float("alpha", m.alpha_u)
    } else {
        float("alpha_u", m.alpha_u) + &float("alpha_v", m.alpha_v)
    };
    format!("<string name=\"distribution\" value=\"{dist}\"/>{alpha}")
}

fn two_sided(id: &str, inner: String) -> String {
    format!("    <bsdf type=\"twosided\" id=\"{id}\">{inner}</bsdf>\n")
}

/// The BSDF element, or `None` for a material this file does not cover.
pub(super) fn bsdf(m: &Material, id: &str) -> Option<String> {
    Some(match m {
        Material::Conductor(c) => two_sided(
            id,
            format!(
                "<bsdf type=\"conductor\">{}{}{}</bsdf>",
                rgb("eta", c.eta),
                rgb("k", c.k),
                rgb("specular_reflectance", c.specular)
            ),
        ),
        Material::RoughConductor(c) => two_sided(
            id,
            format!(
                "<bsdf type=\"roughconductor\">{}{}{}{}</bsdf>",
                roughness(&c.microfacet),
                rgb("eta", c.eta),
                rgb("k", c.k),
                rgb("specular_reflectance", c.specular)
            ),
        ),
        Material::RoughDielectric(d) => format!(
            "    <bsdf type=\"roughdielectric\" id=\"{id}\">{}{}{}{}{}</bsdf>\n",
            roughness(&d.microfacet),
            float("int_ior", d.int_ior),
            float("ext_ior", d.ext_ior),
            rgb("specular_reflectance", d.specular_reflectance),
            rgb("specular_transmittance", d.specular_transmittance)
        ),
        Material::ThinDielectric(t) => format!(
            "    <bsdf type=\"thindielectric\" id=\"{id}\">{}{}{}{}</bsdf>\n",
            float("int_ior", t.int_ior),
            float("ext_ior", t.ext_ior),
            rgb("specular_reflectance", t.specular_reflectance),
            rgb("specular_transmittance", t.specular_transmittance)
        ),
        // A plastic keeps only the ratio of its indices.
        Material::Plastic(p) => two_sided(
            id,
            format!(
                "<bsdf type=\"plastic\">{}{}{}{}<boolean name=\"nonlinear\" value=\"{}\"/></bsdf>",
                rgb("diffuse_reflectance", p.diffuse),
                rgb("specular_reflectance", p.specular),
                float("int_ior", p.eta),
                float("ext_ior", 1.0),
                p.nonlinear
            ),
        ),
        Material::RoughPlastic(p) => two_sided(
            id,
            format!(
                "<bsdf type=\"roughplastic\">{}{}{}{}{}<boolean name=\"nonlinear\" value=\"{}\"/></bsdf>",
                roughness(&p.microfacet),
                rgb("diffuse_reflectance", p.diffuse),
                rgb("specular_reflectance", p.specular),
                float("int_ior", p.eta),
                float("ext_ior", 1.0),
                p.nonlinear
            ),
        ),
        // Nothing there: an index-matched boundary (a medium's).
        Material::Masked(m) if m.opacity == 0.0 => format!("    <bsdf type=\"null\" id=\"{id}\"/>\n"),
        Material::Masked(m) => format!(
            "    <bsdf type=\"mask\" id=\"{id}\">{}<bsdf type=\"twosided\"><bsdf type=\"diffuse\">{}</bsdf></bsdf></bsdf>\n",
            float("opacity", m.opacity),
            rgb("reflectance", m.rho)
        ),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each material's plugin and parameters, as Mitsuba names them.
    #[test]
    fn each_material_writes_its_plugin() {
        let gold = Material::rough_conductor(
            Distribution::Ggx,
            0.1,
            0.3,
            Color::new(0.18, 0.42, 1.37),
            Color::new(3.42, 2.35, 1.77),
            Color::ONE,
        );
        let x = bsdf(&gold, "m").unwrap();
        assert!(x.contains("type=\"twosided\"") && x.contains("type=\"roughconductor\""), "{x}");
        assert!(x.contains("value=\"ggx\"") && x.contains("name=\"alpha_u\" value=\"0.1\"") && x.contains("alpha_v"));
        assert!(x.contains("name=\"eta\" value=\"0.18, 0.42, 1.37\""), "{x}");
        let frosted = Material::rough_dielectric(Distribution::Beckmann, 0.1, 0.1, 1.5, 1.0, Color::ONE, Color::ONE);
        let x = bsdf(&frosted, "g").unwrap();
        assert!(
            x.starts_with("    <bsdf type=\"roughdielectric\" id=\"g\">") && x.contains("name=\"alpha\" value=\"0.1\"")
        );
        assert!(x.contains("name=\"int_ior\" value=\"1.5\""), "{x}");
        let p = Material::rough_plastic(Distribution::Ggx, 0.2, Color::splat(0.5), Color::ONE, 1.49, 1.0, true);
        let x = bsdf(&p, "p").unwrap();
        assert!(x.contains("type=\"roughplastic\"") && x.contains("name=\"nonlinear\" value=\"true\""), "{x}");
        assert!(bsdf(&Material::plastic(Color::ONE, Color::ONE, 1.5, 1.0, false), "q")
            .unwrap()
            .contains("\"plastic\""));
        assert!(bsdf(&Material::thin_dielectric(1.5, 1.0, Color::ONE, Color::ONE), "t")
            .unwrap()
            .contains("thindielectric"));
        assert!(bsdf(&Material::conductor(Color::ZERO, Color::ONE, Color::ONE), "c")
            .unwrap()
            .contains("\"conductor\""));
        assert!(bsdf(&Material::Lambertian { rho: Color::ONE }, "l").is_none());
    }
}
