//! `claims.md` and `claims.csv`.

use std::fmt::Write;

use super::ClaimRow;
use crate::bench::Skipped;

/// A CSV field, quoted where it holds a comma, quote or line break.
fn field(text: &str) -> String {
    if text.contains([',', '"', '\n']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// `claims.csv`: one row per claim and configuration.
pub fn claims_csv(rows: &[ClaimRow], adapter: &str) -> String {
    let mut out = String::from("claim,source,source_figure,measured,configuration,adapter,skew\n");
    for row in rows {
        let measured = row.measured.map_or(String::new(), |m| format!("{m:.4}"));
        let fields = [
            field(&row.claim),
            field(&row.source),
            field(&row.figure),
            measured,
            field(&row.configuration),
            field(adapter),
            field(&row.skew),
        ];
        let _ = writeln!(out, "{}", fields.join(","));
    }
    out
}

/// `claims.md`: the table, the adapter and its timing, the time it took and what could not
/// be measured.
pub fn claims_md(
    rows: &[ClaimRow],
    skipped: &[Skipped],
    adapter: &str,
    timing: &str,
    seconds: f64,
) -> String {
    let mut out = String::from("# The sources' claims, measured\n\n");
    let _ = writeln!(out, "- Adapter: {adapter}");
    let _ = writeln!(out, "- Timing: {timing}");
    let _ = writeln!(out, "- Took {seconds:.0} s");
    let _ = writeln!(
        out,
        "- Ratios come from one run of a few frames (medians), not from the suites' full \
         statistics; the skew column says which way this adapter moves each against the \
         source's GPU.\n"
    );
    let _ = writeln!(
        out,
        "| claim | source | source's figure | measured here | configuration | skew |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|");
    let cell = |text: &str| text.replace('|', "\\|");
    for row in rows {
        let measured = row
            .measured
            .map_or("not measured on this adapter".into(), |m| format!("{m:.3}"));
        let _ = writeln!(
            out,
            "| {} | {} | {} | {measured} | {} | {} |",
            cell(&row.claim),
            cell(&row.source),
            cell(&row.figure),
            cell(&row.configuration),
            cell(&row.skew)
        );
    }
    if !skipped.is_empty() {
        let _ = writeln!(out, "\nNot measured here:\n");
        for s in skipped {
            let _ = writeln!(out, "- {}: {}", s.configuration, s.reason);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_with_commas_and_quotes_are_quoted() {
        assert_eq!(field("a, b"), "\"a, b\"");
        assert_eq!(field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(field("plain"), "plain");
        let row = ClaimRow {
            claim: "maps, volumes".into(),
            source: "seed 003".into(),
            figure: "10-100x".into(),
            measured: Some(12.5),
            configuration: "256x256".into(),
            skew: "up".into(),
        };
        let csv = claims_csv(&[row], "llvmpipe");
        let line = csv.lines().nth(1).unwrap();
        assert_eq!(
            line,
            "\"maps, volumes\",seed 003,10-100x,12.5000,256x256,llvmpipe,up"
        );
    }
}
