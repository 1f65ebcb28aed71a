//! JSON text as penumbra writes its files: pretty-printed, with a final newline.

use serde::Serialize;

/// `value` as pretty-printed JSON with a final newline.
pub fn to_json<T: Serialize>(value: &T) -> String {
    // Serializing plain structs of numbers and strings cannot fail.
    let mut s = serde_json::to_string_pretty(value).expect("serializable output (this is a bug)");
    s.push('\n');
    s
}
