//! Log-log plots of convergence series as SVG (text and lines, no font files needed), and
//! `rt-cli plot` to draw them from `converge` CSV files.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;

use crate::series::{Row, read_csv};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum XAxis {
    /// Seconds of BVH build plus rendering.
    #[default]
    Seconds,
    /// Samples per pixel.
    Spp,
}

#[derive(Args, Debug)]
pub struct PlotArgs {
    /// CSV files written by `rt-cli converge --csv`.
    #[arg(required = true)]
    csv: Vec<PathBuf>,
    /// Output SVG.
    #[arg(short, long)]
    output: PathBuf,
    /// What the horizontal axis shows.
    #[arg(long, value_enum, default_value = "seconds")]
    x: XAxis,
    /// Title above the plot.
    #[arg(long, default_value = "")]
    title: String,
}

pub fn run(args: PlotArgs) -> Result<()> {
    let mut rows = Vec::new();
    for csv in &args.csv {
        rows.extend(read_csv(csv)?);
    }
    let svg = render_svg(&rows, args.x, &args.title)?;
    rt_core::output::write_atomically(&args.output, svg.as_bytes())?;
    Ok(())
}

pub fn save_svg(rows: &[Row], path: &Path) -> Result<()> {
    let svg = render_svg(rows, XAxis::Seconds, "")?;
    rt_core::output::write_atomically(path, svg.as_bytes())
        .with_context(|| format!("writing {}", path.display()))
}

const COLORS: &[&str] = &[
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
];

/// The SVG text of a log-log plot of relMSE against `x`, one line per label, with a slope −1
/// guide (what an unbiased estimator's relMSE does against samples or time).
pub fn render_svg(rows: &[Row], x: XAxis, title: &str) -> Result<String> {
    let points: Vec<(&str, f64, f64)> = rows
        .iter()
        .map(|r| {
            let xv = match x {
                XAxis::Seconds => r.seconds,
                XAxis::Spp => f64::from(r.spp),
            };
            (r.label.as_str(), xv, r.rel_mse)
        })
        .filter(|(_, xv, y)| *xv > 0.0 && *y > 0.0 && xv.is_finite() && y.is_finite())
        .collect();
    anyhow::ensure!(!points.is_empty(), "nothing to plot (no positive values)");
    let mut labels: Vec<&str> = Vec::new();
    for (l, _, _) in &points {
        if !labels.contains(l) {
            labels.push(l);
        }
    }
    let (w, h) = (760.0, 480.0);
    let (left, right, top, bottom) = (80.0, 250.0, 40.0, 60.0);
    let decade = |v: f64, up: bool| {
        if up {
            v.log10().ceil()
        } else {
            v.log10().floor()
        }
    };
    let x0 = decade(points.iter().map(|p| p.1).fold(f64::MAX, f64::min), false);
    let mut x1 = decade(points.iter().map(|p| p.1).fold(f64::MIN, f64::max), true);
    let y0 = decade(points.iter().map(|p| p.2).fold(f64::MAX, f64::min), false);
    let mut y1 = decade(points.iter().map(|p| p.2).fold(f64::MIN, f64::max), true);
    if x1 <= x0 {
        x1 = x0 + 1.0;
    }
    if y1 <= y0 {
        y1 = y0 + 1.0;
    }
    let px = |v: f64| left + (v.log10() - x0) / (x1 - x0) * (w - left - right);
    let py = |v: f64| h - bottom - (v.log10() - y0) / (y1 - y0) * (h - top - bottom);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="22" font-size="15" text-anchor="middle">{}</text>"#,
        (left + w - right) / 2.0,
        escape(title)
    );
    for d in (x0 as i32)..=(x1 as i32) {
        let xp = px(10f64.powi(d));
        let _ = writeln!(
            s,
            r##"<line x1="{xp}" y1="{top}" x2="{xp}" y2="{}" stroke="#ddd"/><text x="{xp}" y="{}" text-anchor="middle">1e{d}</text>"##,
            h - bottom,
            h - bottom + 18.0
        );
    }
    for d in (y0 as i32)..=(y1 as i32) {
        let yp = py(10f64.powi(d));
        let _ = writeln!(
            s,
            r##"<line x1="{left}" y1="{yp}" x2="{}" y2="{yp}" stroke="#ddd"/><text x="{}" y="{}" text-anchor="end">1e{d}</text>"##,
            w - right,
            left - 6.0,
            yp + 4.0
        );
    }
    let _ = writeln!(
        s,
        r#"<rect x="{left}" y="{top}" width="{}" height="{}" fill="none" stroke="black"/>"#,
        w - left - right,
        h - top - bottom
    );
    let x_name = match x {
        XAxis::Seconds => "time to image (s: BVH build + render)",
        XAxis::Spp => "samples per pixel",
    };
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">{x_name}</text>"#,
        (left + w - right) / 2.0,
        h - 16.0
    );
    let _ = writeln!(
        s,
        r#"<text transform="translate(20 {}) rotate(-90)" text-anchor="middle">relMSE against the reference</text>"#,
        (top + h - bottom) / 2.0
    );
    // Slope −1 guide through the first point of the first series.
    let (_, gx, gy) = points[0];
    let gx1 = 10f64.powf(x1);
    let _ = writeln!(
        s,
        r##"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="#999" stroke-dasharray="5 4"/>"##,
        px(gx),
        py(gy),
        px(gx1),
        py(gy * gx / gx1)
    );
    for (i, label) in labels.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        let series: Vec<String> = points
            .iter()
            .filter(|p| p.0 == *label)
            .map(|p| format!("{:.2},{:.2}", px(p.1), py(p.2)))
            .collect();
        let _ = writeln!(
            s,
            r#"<polyline points="{}" fill="none" stroke="{color}" stroke-width="2"/>"#,
            series.join(" ")
        );
        for p in &series {
            let (cx, cy) = p.split_once(',').unwrap_or(("0", "0"));
            let _ = writeln!(s, r#"<circle cx="{cx}" cy="{cy}" r="2.5" fill="{color}"/>"#);
        }
        let ly = top + 14.0 + i as f64 * 18.0;
        let lx = w - right + 12.0;
        let _ = writeln!(
            s,
            r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{color}" stroke-width="3"/><text x="{}" y="{}">{}</text>"#,
            lx + 18.0,
            lx + 24.0,
            ly + 4.0,
            escape(label)
        );
    }
    let ly = top + 14.0 + labels.len() as f64 * 18.0;
    let lx = w - right + 12.0;
    let _ = writeln!(
        s,
        r##"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="#999" stroke-dasharray="5 4"/><text x="{}" y="{}">slope −1</text>"##,
        lx + 18.0,
        lx + 24.0,
        ly + 4.0
    );
    s.push_str("</svg>\n");
    Ok(s)
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(label: &str, spp: u32, seconds: f64, rel_mse: f64) -> Row {
        Row {
            label: label.into(),
            spp,
            seconds,
            rel_mse,
            rmse: 0.0,
            mean_ratio: [1.0; 3],
            bvh_ms: 0.0,
        }
    }

    #[test]
    fn the_plot_has_one_line_per_series_and_escapes_labels() {
        let rows = vec![
            row("a<b", 1, 0.1, 1.0),
            row("a<b", 2, 0.2, 0.5),
            row("c", 1, 0.05, 2.0),
            row("c", 2, 0.1, 1.0),
        ];
        let svg = render_svg(&rows, XAxis::Seconds, "t").expect("plots");
        assert_eq!(svg.matches("<polyline").count(), 2);
        assert!(svg.contains("a&lt;b") && !svg.contains("a<b"));
        assert!(render_svg(&[], XAxis::Spp, "").is_err());
    }
}
