//! The RON files the app reads (bench suites, the claims list, viewer settings), read and
//! parsed in one place, with errors that name the file, line and column.

use std::path::Path;

use serde::de::DeserializeOwned;

/// Reads `path` as RON of type `T`. A missing or unreadable file says which; a malformed one
/// says `file:line:column: what is wrong`.
pub fn load<T: DeserializeOwned>(path: &Path) -> anyhow::Result<T> {
    let text =
        std::fs::read_to_string(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    ron::from_str(&text).map_err(|e| {
        anyhow::anyhow!(
            "{}:{}:{}: {}",
            path.display(),
            e.span.start.line,
            e.span.start.col,
            e.code
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, serde::Deserialize, PartialEq)]
    struct Pair {
        name: String,
        count: u32,
    }

    #[test]
    fn files_parse_or_say_where_they_are_wrong() {
        let folder = std::env::temp_dir().join(format!("zoo-ron-file-{}", std::process::id()));
        std::fs::create_dir_all(&folder).unwrap();
        let good = folder.join("good.ron");
        std::fs::write(&good, "(name: \"a\", count: 3)").unwrap();
        let pair: Pair = load(&good).unwrap();
        assert_eq!(
            pair,
            Pair {
                name: "a".into(),
                count: 3
            }
        );
        let bad = folder.join("bad.ron");
        std::fs::write(&bad, "(\n  name: \"a\",\n  count: -1,\n)").unwrap();
        let err = load::<Pair>(&bad).unwrap_err().to_string();
        assert!(err.starts_with(&format!("{}:3:", bad.display())), "{err}");
        let missing = folder.join("missing.ron");
        let err = load::<Pair>(&missing).unwrap_err().to_string();
        assert!(
            err.starts_with(&format!("{}: ", missing.display())),
            "{err}"
        );
        std::fs::remove_dir_all(&folder).unwrap();
    }
}
