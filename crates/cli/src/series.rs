//! Convergence series: one measured step of `rt-cli converge` per `Row`, and the CSV files that
//! `converge` appends them to and `plot` reads, in one place (both commands use this format, so it
//! belongs to neither).

use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};

/// One measured step.
#[derive(Clone, Debug)]
pub struct Row {
    pub label: String,
    pub spp: u32,
    pub seconds: f64,
    pub rel_mse: f64,
    pub rmse: f64,
    pub mean_ratio: [f64; 3],
    pub bvh_ms: f64,
}

const CSV_HEADER: &str =
    "label,spp,seconds,rel_mse,rmse,mean_ratio_r,mean_ratio_g,mean_ratio_b,bvh_build_ms";

impl Row {
    pub fn csv(&self) -> String {
        format!(
            "{},{},{:.6},{:.6e},{:.6e},{:.6},{:.6},{:.6},{:.3}",
            self.label.replace(',', ";"),
            self.spp,
            self.seconds,
            self.rel_mse,
            self.rmse,
            self.mean_ratio[0],
            self.mean_ratio[1],
            self.mean_ratio[2],
            self.bvh_ms
        )
    }

    pub fn parse(line: &str) -> Option<Row> {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != 9 {
            return None;
        }
        Some(Row {
            label: f[0].to_string(),
            spp: f[1].parse().ok()?,
            seconds: f[2].parse().ok()?,
            rel_mse: f[3].parse().ok()?,
            rmse: f[4].parse().ok()?,
            mean_ratio: [f[5].parse().ok()?, f[6].parse().ok()?, f[7].parse().ok()?],
            bvh_ms: f[8].parse().ok()?,
        })
    }
}

/// Appends `rows` to the CSV file at `path`, writing the header first when the file is new.
pub fn append_csv(path: &Path, rows: &[Row]) -> Result<()> {
    let exists = path.exists();
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .with_context(|| format!("opening {}", path.display()))?;
    let mut text = String::new();
    if !exists {
        text.push_str(CSV_HEADER);
        text.push('\n');
    }
    for row in rows {
        text.push_str(&row.csv());
        text.push('\n');
    }
    file.write_all(text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))
}

/// Every row of a CSV file `append_csv` wrote.
pub fn read_csv(path: &Path) -> Result<Vec<Row>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        rows.push(
            Row::parse(line)
                .with_context(|| format!("{}:{}: not a converge row", path.display(), i + 1))?,
        );
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_rows_round_trip() {
        let r = Row {
            label: "x".into(),
            spp: 4,
            seconds: 1.5,
            rel_mse: 0.25,
            rmse: 0.0,
            mean_ratio: [1.0; 3],
            bvh_ms: 0.0,
        };
        let parsed = Row::parse(&r.csv()).expect("parses");
        assert_eq!((parsed.label, parsed.spp), ("x".to_string(), 4));
        assert!((parsed.rel_mse - 0.25).abs() < 1e-9);
    }
}
