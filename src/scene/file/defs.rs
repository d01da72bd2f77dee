//! The scene file's top level as serde reads it: every value with its byte
//! span, every table refusing fields it does not know (each section's
//! table is defined beside the code that checks it).

use super::camera::CameraDef;
use super::light::LightDef;
use super::material::MaterialDef;
use super::shape::ShapeDef;
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
