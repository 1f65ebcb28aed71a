//! Counting repairs for warnings: how many faces each repair touched, and where the first few are.

use std::fmt;

/// How many examples a warning names.
const EXAMPLES: usize = 3;

/// Where a face came from: its surface name and, when known, its line in the OBJ file.
#[derive(Clone, Debug)]
pub(crate) struct FaceSource {
    pub name: String,
    pub line: Option<usize>,
}

impl fmt::Display for FaceSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{} at line {line}", self.name),
            None => write!(f, "{}", self.name),
        }
    }
}

/// The faces one kind of repair touched: a count and the first few.
#[derive(Clone, Debug, Default)]
pub(crate) struct Tally {
    count: usize,
    examples: Vec<String>,
}

impl Tally {
    pub(crate) fn note(&mut self, source: &FaceSource) {
        self.count += 1;
        if self.examples.len() < EXAMPLES {
            self.examples.push(source.to_string());
        }
    }

    /// `"{action} {count} {what} (first: a at line 3, b at line 9, ...)"` (no action when it is
    /// empty), or `None` when nothing was noted. `what` should read well after a count ("faces
    /// with zero area").
    pub(crate) fn describe(&self, action: &str, what: &str) -> Option<String> {
        if self.count == 0 {
            return None;
        }
        let more = if self.count > self.examples.len() {
            ", ..."
        } else {
            ""
        };
        let count = thousands(self.count);
        let head = if action.is_empty() {
            count
        } else {
            format!("{action} {count}")
        };
        Some(format!(
            "{head} {what} (first: {}{more})",
            self.examples.join(", ")
        ))
    }
}

/// `10240` as `"10,240"`: counts of faces run to six digits and more.
pub(crate) fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_read_with_separators() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1000), "1,000");
        assert_eq!(thousands(10240), "10,240");
        assert_eq!(thousands(1234567), "1,234,567");
    }

    #[test]
    fn names_the_first_few() {
        let mut tally = Tally::default();
        assert_eq!(tally.describe("dropped", "faces"), None);
        for i in 0..5 {
            tally.note(&FaceSource {
                name: format!("wall/white/{i}"),
                line: Some(10 + i),
            });
        }
        assert_eq!(
            tally.describe("dropped", "faces with zero area").as_deref(),
            Some(
                "dropped 5 faces with zero area (first: wall/white/0 at line 10, wall/white/1 at line 11, \
                 wall/white/2 at line 12, ...)"
            )
        );
    }
}
