//! glTF materials as reflectance and emission.
//!
//! The reflectance is `baseColorFactor`'s linear RGB, channels at or above 1 clamped to
//! [`MAX_OBJ_REFLECTANCE`] as for OBJ. `emissiveFactor` times the
//! `KHR_materials_emissive_strength` strength (1 without it) is the surface's radiance in
//! W/(m²·sr) per channel; a diffuse emitter's exitance is π times its radiance. Textures are not
//! read: a material with one is lit with its factor, and warned of.

use std::f64::consts::PI;

use crate::color::Rgb;
use crate::obj::MAX_OBJ_REFLECTANCE;

/// One material as the scene uses it.
#[derive(Clone, Debug)]
pub(crate) struct Material {
    pub name: String,
    pub reflectance: Rgb,
    pub emission: Rgb,
    base_color: [f64; 3],
    textures: Vec<&'static str>,
}

/// The file's materials by index, then glTF's default material (white, not emitting) for
/// primitives that name none.
pub(crate) fn materials(document: &gltf::Document) -> Vec<Material> {
    let mut out: Vec<Material> = document.materials().map(|m| material(&m)).collect();
    out.push(Material {
        name: "default-material".to_string(),
        reflectance: Rgb::splat(MAX_OBJ_REFLECTANCE),
        emission: Rgb::ZERO,
        base_color: [1.0; 3],
        textures: Vec::new(),
    });
    out
}

fn material(m: &gltf::Material) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, _] = pbr.base_color_factor().map(f64::from);
    let strength = m.emissive_strength().map_or(1.0, f64::from);
    let radiance = Rgb::from(m.emissive_factor().map(f64::from)) * strength;
    let mut textures = Vec::new();
    if pbr.base_color_texture().is_some() {
        textures.push("baseColorTexture");
    }
    if m.emissive_texture().is_some() {
        textures.push("emissiveTexture");
    }
    let name = m.name().map_or_else(
        || format!("material{}", m.index().unwrap_or(0)),
        str::to_string,
    );
    Material {
        name,
        reflectance: Rgb::from([r, g, b]).map(|c| if c >= 1.0 { MAX_OBJ_REFLECTANCE } else { c }),
        emission: radiance * PI,
        base_color: [r, g, b],
        textures,
    }
}

/// What loading changed or left out of each of the materials `used`: clamped reflectance and
/// textures, a line each.
pub(crate) fn warnings(materials: &[Material], used: &[usize]) -> Vec<String> {
    let mut out = Vec::new();
    for (i, m) in used.iter().filter_map(|&i| Some((i, materials.get(i)?))) {
        let [r, g, b] = m.base_color;
        if i + 1 == materials.len() {
            out.push(format!(
                "faces without a material get glTF's default material, white: reflectance \
                 {MAX_OBJ_REFLECTANCE}"
            ));
        } else if m.base_color.iter().any(|&c| c >= 1.0) {
            out.push(format!(
                "material \"{}\" has baseColorFactor {r} {g} {b}: a surface cannot reflect all \
                 the light it receives, so its channels at or above 1 become {MAX_OBJ_REFLECTANCE}",
                m.name
            ));
        }
        for texture in &m.textures {
            let used = if *texture == "baseColorTexture" {
                format!("reflectance {}", channels(m.reflectance))
            } else {
                format!("exitance {} W/m²", channels(m.emission))
            };
            out.push(format!(
                "material \"{}\" has a {texture}, which is not read: its factor alone gives the \
                 {used}",
                m.name
            ));
        }
    }
    out
}

/// `r g b`, as short as each number allows.
fn channels(c: Rgb) -> String {
    let [r, g, b] = c.to_array();
    format!("{r} {g} {b}")
}
