//! Fingerprints that tell runs and scenes apart (shards of one run, a replay of a report's
//! scene): FNV-1a over their JSON forms.

use penumbra_scenes::LoadedScene;

/// FNV-1a, 64 bits: a fingerprint against mixing up runs, not a cryptographic hash.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The fingerprint of some bytes, as 16 hex digits.
pub(crate) fn hex(bytes: &[u8]) -> String {
    format!("{:016x}", fnv1a(bytes))
}

/// The fingerprint of a scene: of its JSON form, so of every number in it.
pub fn scene_fingerprint(loaded: &LoadedScene) -> String {
    hex(serde_json::to_string(&loaded.scene)
        .unwrap_or_default()
        .as_bytes())
}
