//! A figure drawn at a resolution ([`super::Chart::dpi`]): [`Scaled`] shows the drawing
//! code a picture of the figure's size in 1/150 inch and draws everything (coordinates,
//! line widths, radii, font sizes) `scale` times larger on the backend below, so that one
//! layout gives every resolution and text is rasterised at its final size (not an
//! enlarged bitmap).

use plotters::prelude::*;
use plotters::style::text_anchor::Pos;
use plotters::style::{FontDesc, TextStyle};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingErrorKind,
};

/// `inner` seen as a picture of `size` (the figure's logical pixels), scaled by `scale`.
pub(super) struct Scaled<B> {
    inner: B,
    size: (u32, u32),
    scale: f64,
}

impl<B: DrawingBackend> Scaled<B> {
    /// `inner` (of `size · scale` pixels) drawn on as a picture of `size`.
    pub(super) fn new(inner: B, size: (u32, u32), scale: f64) -> Self {
        Self { inner, size, scale }
    }

    fn at(&self, (x, y): BackendCoord) -> BackendCoord {
        (
            (f64::from(x) * self.scale).round() as i32,
            (f64::from(y) * self.scale).round() as i32,
        )
    }

    /// A length (a line's width, a radius): scaled, at least one pixel.
    fn length(&self, n: u32) -> u32 {
        ((f64::from(n) * self.scale).round() as u32).max(1)
    }

    fn style<S: BackendStyle>(&self, style: &S) -> Stroke {
        Stroke {
            colour: style.color(),
            width: self.length(style.stroke_width()),
        }
    }
}

/// A colour and a line width in the backend's pixels.
struct Stroke {
    colour: BackendColor,
    width: u32,
}

impl BackendStyle for Stroke {
    fn color(&self) -> BackendColor {
        self.colour
    }

    fn stroke_width(&self) -> u32 {
        self.width
    }
}

type Failure<B> = DrawingErrorKind<<B as DrawingBackend>::ErrorType>;

impl<B: DrawingBackend> DrawingBackend for Scaled<B> {
    type ErrorType = B::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.size
    }

    fn ensure_prepared(&mut self) -> Result<(), Failure<B>> {
        self.inner.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), Failure<B>> {
        self.inner.present()
    }

    fn draw_pixel(&mut self, point: BackendCoord, colour: BackendColor) -> Result<(), Failure<B>> {
        // A logical pixel is a block of backend pixels.
        let (x0, y0) = self.at(point);
        let (x1, y1) = self.at((point.0 + 1, point.1 + 1));
        let fill = Stroke { colour, width: 1 };
        self.inner
            .draw_rect((x0, y0), (x1 - 1, y1 - 1), &fill, true)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), Failure<B>> {
        let stroke = self.style(style);
        let (from, to) = (self.at(from), self.at(to));
        if stroke.width > 1 {
            // As plotters draws a wide path: a polygon around it.
            return self.inner.draw_path([from, to], &stroke);
        }
        self.inner.draw_line(from, to, &stroke)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), Failure<B>> {
        let stroke = self.style(style);
        let (a, b) = (self.at(upper_left), self.at(bottom_right));
        self.inner.draw_rect(a, b, &stroke, fill)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), Failure<B>> {
        let stroke = self.style(style);
        let points: Vec<BackendCoord> = path.into_iter().map(|p| self.at(p)).collect();
        self.inner.draw_path(points, &stroke)
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), Failure<B>> {
        let stroke = self.style(style);
        let (center, radius) = (self.at(center), self.length(radius));
        self.inner.draw_circle(center, radius, &stroke, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), Failure<B>> {
        let stroke = self.style(style);
        let points: Vec<BackendCoord> = vert.into_iter().map(|p| self.at(p)).collect();
        self.inner.fill_polygon(points, &stroke)
    }

    fn draw_text<T: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &T,
        pos: BackendCoord,
    ) -> Result<(), Failure<B>> {
        // The same font, anchor, turn and colour at the scaled size.
        let font = FontDesc::new(style.family(), style.size() * self.scale, style.style())
            .transform(style.transform());
        let scaled = TextStyle {
            font,
            color: style.color(),
            pos: Pos::new(style.anchor().h_pos, style.anchor().v_pos),
        };
        let pos = self.at(pos);
        self.inner.draw_text(text, &scaled, pos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dark pixels of a filled rectangle from (10, 20) to (30, 40) drawn at `scale`
    /// on a picture of 100 x 100, and the first of them (row by row).
    fn rectangle(scale: u32) -> (usize, (u32, u32)) {
        let side = 100 * scale;
        let mut pixels = vec![255u8; (3 * side * side) as usize];
        {
            let backend = BitMapBackend::with_buffer(&mut pixels, (side, side));
            let mut scaled = Scaled::new(backend, (100, 100), f64::from(scale));
            assert_eq!(scaled.get_size(), (100, 100));
            scaled.draw_rect((10, 20), (30, 40), &BLACK, true).unwrap();
            scaled.present().unwrap();
        }
        let dark: Vec<(u32, u32)> = (0..side)
            .flat_map(|y| (0..side).map(move |x| (x, y)))
            .filter(|&(x, y)| pixels[(3 * (y * side + x)) as usize] == 0)
            .collect();
        (dark.len(), dark[0])
    }

    /// At twice the resolution the rectangle covers four times the pixels, from twice
    /// its corner.
    #[test]
    fn coordinates_are_scaled() {
        let (once, corner) = rectangle(1);
        assert_eq!(corner, (10, 20));
        assert_eq!(rectangle(2), (4 * once, (20, 40)));
        assert_eq!(rectangle(3), (9 * once, (30, 60)));
    }

    /// A line 2 wide at scale 1.5 is 3 wide.
    #[test]
    fn widths_and_radii_are_scaled_and_at_least_one_pixel() {
        let mut pixels = vec![0u8; 3 * 30 * 30];
        let backend = BitMapBackend::with_buffer(&mut pixels, (30, 30));
        let scaled = Scaled::new(backend, (20, 20), 1.5);
        assert_eq!(scaled.length(2), 3);
        assert_eq!(scaled.length(0), 1);
        assert_eq!(scaled.at((3, 7)), (5, 11)); // 4.5 and 10.5 rounded away from zero
    }
}
