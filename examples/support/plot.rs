//! A minimal plot written as PNG (the `png` crate encodes; this only rasterises): a
//! frame, tick marks every tenth of each axis range, polylines and colour maps. No text:
//! the examples write the numbers as CSV next to the picture.
#![allow(dead_code)] // each example uses its own part

/// Distinct line colours.
pub const COLOURS: [[u8; 3]; 8] = [
    [20, 60, 200],
    [200, 30, 30],
    [20, 150, 60],
    [200, 120, 0],
    [140, 40, 170],
    [0, 150, 170],
    [120, 120, 120],
    [0, 0, 0],
];

/// Diverging colour of `t ∈ [-1, 1]`: blue (−1), white (0), red (+1).
pub fn diverging(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(-1.0, 1.0) };
    let fade = |c: f64| (255.0 * (1.0 - t.abs()) + c * t.abs()).round() as u8;
    if t < 0.0 {
        [fade(20.0), fade(60.0), fade(200.0)]
    } else {
        [fade(200.0), fade(30.0), fade(30.0)]
    }
}

use std::fs::File;
use std::io::BufWriter;

/// A white RGB canvas with a plotting frame.
pub struct Plot {
    width: usize,
    height: usize,
    pixels: Vec<u8>,
    x_range: (f64, f64),
    y_range: (f64, f64),
    margin: usize,
}

impl Plot {
    /// A canvas of `width x height` pixels mapping `x_range x y_range`.
    pub fn new(width: usize, height: usize, x_range: (f64, f64), y_range: (f64, f64)) -> Self {
        let mut plot = Self {
            width,
            height,
            pixels: vec![255; width * height * 3],
            x_range,
            y_range,
            margin: 40,
        };
        plot.frame();
        plot
    }

    fn put(&mut self, x: i64, y: i64, rgb: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as usize) < self.width && (y as usize) < self.height {
            let k = (y as usize * self.width + x as usize) * 3;
            self.pixels[k..k + 3].copy_from_slice(&rgb);
        }
    }

    fn to_pixel(&self, x: f64, y: f64) -> (f64, f64) {
        let m = self.margin as f64;
        let w = (self.width - 2 * self.margin) as f64;
        let h = (self.height - 2 * self.margin) as f64;
        let px = m + (x - self.x_range.0) / (self.x_range.1 - self.x_range.0) * w;
        let py =
            self.height as f64 - m - (y - self.y_range.0) / (self.y_range.1 - self.y_range.0) * h;
        (px, py)
    }

    fn segment(&mut self, a: (f64, f64), b: (f64, f64), rgb: [u8; 3]) {
        let steps = ((b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil() as usize).max(1);
        for s in 0..=steps {
            let t = s as f64 / steps as f64;
            let x = a.0 + t * (b.0 - a.0);
            let y = a.1 + t * (b.1 - a.1);
            self.put(x.round() as i64, y.round() as i64, rgb);
            self.put(x.round() as i64 + 1, y.round() as i64, rgb);
        }
    }

    fn frame(&mut self) {
        let (x0, x1, y0, y1) = (
            self.x_range.0,
            self.x_range.1,
            self.y_range.0,
            self.y_range.1,
        );
        let black = [0, 0, 0];
        let corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)];
        for w in corners.windows(2) {
            let (a, b) = (self.to_pixel(w[0].0, w[0].1), self.to_pixel(w[1].0, w[1].1));
            self.segment(a, b, black);
        }
        for k in 0..=10 {
            let x = x0 + (x1 - x0) * k as f64 / 10.0;
            let y = y0 + (y1 - y0) * k as f64 / 10.0;
            let p = self.to_pixel(x, y0);
            self.segment(p, (p.0, p.1 + 6.0), black);
            let q = self.to_pixel(x0, y);
            self.segment(q, (q.0 - 6.0, q.1), black);
        }
    }

    /// Draws the polyline through `points` (data coordinates).
    pub fn line(&mut self, points: &[(f64, f64)], rgb: [u8; 3]) {
        for w in points.windows(2) {
            let (a, b) = (self.to_pixel(w[0].0, w[0].1), self.to_pixel(w[1].0, w[1].1));
            self.segment(a, b, rgb);
        }
    }

    /// Fills the data area with `values` (`columns x rows`, row-major, row 0 at the bottom
    /// of the y range) through `colour`.
    pub fn heatmap(
        &mut self,
        values: &[f64],
        columns: usize,
        rows: usize,
        colour: impl Fn(f64) -> [u8; 3],
    ) {
        let (x0, y0) = self.to_pixel(self.x_range.0, self.y_range.0);
        let (x1, y1) = self.to_pixel(self.x_range.1, self.y_range.1);
        for py in (y1.ceil() as i64)..(y0.floor() as i64) {
            for px in (x0.ceil() as i64 + 1)..(x1.floor() as i64) {
                let fx = (px as f64 - x0) / (x1 - x0);
                let fy = (y0 - py as f64) / (y0 - y1);
                let c = ((fx * columns as f64) as usize).min(columns - 1);
                let r = ((fy * rows as f64) as usize).min(rows - 1);
                self.put(px, py, colour(values[r * columns + c]));
            }
        }
    }

    /// Writes the canvas as an 8-bit RGB PNG.
    pub fn save(&self, path: &str) -> Result<(), crate::report::FileError> {
        use crate::report::AtPath;
        let file = BufWriter::new(File::create(path).at("create", path)?);
        let mut encoder = png::Encoder::new(file, self.width as u32, self.height as u32);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().at("write", path)?;
        writer.write_image_data(&self.pixels).at("write", path)?;
        // Dropping the writer would finish the file and swallow an error.
        writer.finish().at("write", path)
    }
}
