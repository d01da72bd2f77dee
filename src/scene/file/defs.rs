//! The scene file's structure as serde reads it: every value with its
//! byte span, every table refusing fields it does not know.

use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

pub type V3 = [f32; 3];

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileDef {
    pub camera: Spanned<CameraDef>,
    pub ambient: Option<Spanned<V3>>,
    #[serde(default)]
    pub materials: BTreeMap<String, Spanned<MaterialDef>>,
    #[serde(default)]
    pub shapes: Vec<Spanned<ShapeDef>>,
    #[serde(default)]
    pub lights: Vec<Spanned<LightDef>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDef {
    pub eye: Spanned<V3>,
    pub lower_left: Option<Spanned<V3>>,
    pub lower_right: Option<Spanned<V3>>,
    pub upper_left: Option<Spanned<V3>>,
    pub upper_right: Option<Spanned<V3>>,
    pub target: Option<Spanned<V3>>,
    pub up: Option<Spanned<V3>>,
    pub vfov: Option<Spanned<f32>>,
    pub width: Spanned<i64>,
    pub height: Spanned<i64>,
    pub rays_per_pixel_edge: Option<Spanned<i64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDef {
    #[serde(rename = "type")]
    pub kind: Spanned<String>,
    pub rho: Option<Spanned<V3>>,
    pub reflectance: Option<Spanned<V3>>,
    pub ior: Option<Spanned<f32>>,
    pub absorption: Option<Spanned<V3>>,
    pub color: Option<Spanned<V3>>,
    pub m_a: Option<Spanned<f32>>,
    pub m_l: Option<Spanned<f32>>,
    pub m_s: Option<Spanned<f32>>,
    pub m_sm: Option<Spanned<f32>>,
    pub m_sp: Option<Spanned<f32>>,
    pub m_r: Option<Spanned<f32>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeDef {
    #[serde(rename = "type")]
    pub kind: Spanned<String>,
    pub material: Option<Spanned<String>>,
    pub emission: Option<Spanned<V3>>,
    pub vertices: Option<Spanned<Vec<V3>>>,
    pub center: Option<Spanned<V3>>,
    pub radius: Option<Spanned<f32>>,
    pub normal: Option<Spanned<V3>>,
    pub file: Option<Spanned<String>>,
    pub transform: Option<Vec<Spanned<StepDef>>>,
    pub floor: Option<Spanned<String>>,
    pub ceiling: Option<Spanned<String>>,
    pub walls: Option<Spanned<Vec<Spanned<String>>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepDef {
    pub translate: Option<Spanned<V3>>,
    pub rotate: Option<Spanned<RotateDef>>,
    pub scale: Option<Spanned<V3>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotateDef {
    pub axis: Spanned<V3>,
    pub degrees: Spanned<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightDef {
    #[serde(rename = "type")]
    pub kind: Spanned<String>,
    pub center: Option<Spanned<V3>>,
    pub normal: Option<Spanned<V3>>,
    pub radius: Option<Spanned<f32>>,
    pub radiance: Option<Spanned<V3>>,
    pub position: Option<Spanned<V3>>,
    pub direction: Option<Spanned<V3>>,
    pub color: Option<Spanned<V3>>,
    pub falloff: Option<Spanned<f32>>,
    pub dead_distance: Option<Spanned<f32>>,
}
