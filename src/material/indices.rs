//! Indices of refraction by name, and a conductor's complex index by
//! name or by value: one definition for both scene front-ends (Mitsuba
//! 3's `int_ior` and `ext_ior`, a number or a name, and a conductor's
//! `material`, `eta` and `k`; src/bsdfs/dielectric.cpp, conductor.cpp).

use super::defaults::{CONDUCTOR_ETA, CONDUCTOR_K};
use crate::math::Color;

/// The named indices that are Mitsuba's defaults: "bk7" (dielectrics),
/// "polypropylene" (plastics) and "air" (outside).
pub const BK7: f32 = 1.5046;
pub const POLYPROPYLENE: f32 = 1.49;
pub const AIR: f32 = 1.000277;

/// Named indices of refraction, as Mitsuba 3's `dielectric` documentation
/// lists them (values at about 589 nm; they are the usual handbook figures,
/// e.g. the CRC Handbook of Chemistry and Physics and Schott's BK7 sheet).
pub const NAMED_IOR: [(&str, f32); 23] = [
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", AIR),
    ("carbon dioxide", 1.00045),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", POLYPROPYLENE),
    ("bk7", BK7),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

/// The index of refraction named `name` (in any case), or `None`.
pub fn named_ior(name: &str) -> Option<f32> {
    NAMED_IOR.iter().find(|(n, _)| n.eq_ignore_ascii_case(name)).map(|&(_, v)| v)
}

/// An index of refraction given by its name: the value, or what is wrong.
pub fn index_named(name: &str) -> Result<f32, String> {
    named_ior(name)
        .ok_or_else(|| format!("'{name}' is not a named index of refraction (e.g. bk7, water, air, diamond)"))
}

/// The conductor Mitsuba calls `none`: a perfect mirror, eta 0 + 1i.
pub const NO_CONDUCTOR: &str = "none";

/// A conductor's complex index (eta, k): a named `material` (Mitsuba's
/// list, [`super::conductors`]), or `eta` and `k`, each defaulting to the
/// perfect mirror's (which `material = "none"` names too); a name and a
/// value together are refused, as Mitsuba refuses them.
pub fn complex_index(material: Option<&str>, eta: Option<Color>, k: Option<Color>) -> Result<(Color, Color), String> {
    match material {
        Some(m) if m != NO_CONDUCTOR => {
            if eta.is_some() || k.is_some() {
                return Err(format!("give either eta and k or a material ('{m}'), not both"));
            }
            super::conductors::named_conductor(m)
                .ok_or_else(|| format!("'{m}' is not a conductor Mitsuba names (e.g. Au, Ag, Al, Cu, Cr)"))
        }
        _ => Ok((eta.unwrap_or(Color::splat(CONDUCTOR_ETA)), k.unwrap_or(Color::splat(CONDUCTOR_K)))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_indices_are_found_in_any_case_and_hold_the_defaults() {
        assert_eq!(named_ior("BK7"), Some(1.5046));
        assert_eq!(named_ior("water"), Some(1.333));
        assert_eq!(named_ior("unobtainium"), None);
        assert!(index_named("unobtainium").unwrap_err().contains("unobtainium"));
        assert_eq!(named_ior("air"), Some(AIR));
        assert_eq!(named_ior("polypropylene"), Some(POLYPROPYLENE));
    }

    #[test]
    fn a_complex_index_is_named_or_given_never_both() {
        let (eta, k) = complex_index(Some("Au"), None, None).unwrap();
        assert_eq!(Some((eta, k)), super::super::conductors::named_conductor("Au"));
        let given = (Color::splat(0.2), Color::splat(3.0));
        assert_eq!(complex_index(None, Some(given.0), Some(given.1)), Ok(given));
        assert_eq!(complex_index(Some("none"), None, None), Ok((Color::ZERO, Color::ONE)));
        assert!(complex_index(Some("Au"), Some(given.0), None).unwrap_err().contains("not both"));
        assert!(complex_index(Some("gold"), None, None).unwrap_err().contains("'gold'"));
    }
}
