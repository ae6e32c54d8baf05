//! Psychophysical stimuli synthesised as contrast patterns s(x, y) ∈ [−1, 1], for the
//! calibration checks: a stimulus of Michelson contrast c on a background of luminance L0 is
//! L0·(1 + c·s). Gabors (a cosine carrier under a Gaussian), gratings in a square, tapered or
//! circular aperture, and discs (a grating of frequency 0 in a circle), as castleCSF's datasets
//! and Foley 1994 describe them.
//!
//! Conventions (the datasets give frequency, σ or area, and orientation, not a raster): the carrier
//! is in cosine phase about the stimulus centre (ModelFest's and castleCSF's Gabors are even);
//! orientation 0 is a vertical grating (luminance varies along x); a square aperture of area A has
//! side √A with hard edges, a tapered one the same side with raised-cosine edges over its outer
//! eighth on each side (Wright 1983's "tapered rectangular" field; the taper's width is our
//! assumption), a circle of area A radius √(A/π). Hard edges are antialiased (4 × 4 samples per
//! pixel for the aperture).
//!
//! The raster ([`raster_for`]) is chosen per stimulus: at least [`PX_PER_CYCLE`] pixels per
//! cycle and [`MIN_PX_ACROSS`] pixels across the stimulus, with a uniform margin of background
//! around it, and at most [`MAX_SIDE`] pixels a side (fewer pixels per cycle first, down to
//! [`MIN_PX_PER_CYCLE`]; a stimulus that needs more is not rendered and is reported as such).

use std::f64::consts::PI;

/// Pixels per cycle of the carrier wanted.
pub const PX_PER_CYCLE: f64 = 6.0;
/// Fewest pixels per cycle accepted when the stimulus is large.
pub const MIN_PX_PER_CYCLE: f64 = 3.0;
/// Fewest pixels across the stimulus.
pub const MIN_PX_ACROSS: f64 = 32.0;
/// The raster's side is this many times the stimulus's extent (a margin of a quarter of the
/// extent on each side), plus [`MARGIN_PX`].
pub const FIELD: f64 = 1.5;
/// Extra background pixels on each side.
pub const MARGIN_PX: usize = 8;
/// Largest raster side, pixels.
pub const MAX_SIDE: usize = 1536;

/// The window a carrier is seen through.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Aperture {
    /// A Gaussian of standard deviation `sigma` degrees.
    Gauss {
        /// σ, degrees.
        sigma: f64,
    },
    /// A square of side `side` degrees, hard edges.
    Square {
        /// Side, degrees.
        side: f64,
    },
    /// A square of side `side` degrees with raised-cosine edges.
    Tapered {
        /// Side at half amplitude, degrees.
        side: f64,
    },
    /// A disc of radius `radius` degrees, hard edge.
    Circle {
        /// Radius, degrees.
        radius: f64,
    },
}

/// A carrier of `frequency` cycles per degree (0: uniform, a disc or square of light) at
/// `orientation` degrees, through an aperture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grating {
    /// Cycles per degree.
    pub frequency: f64,
    /// Degrees; 0 is a vertical grating.
    pub orientation: f64,
    /// The window.
    pub aperture: Aperture,
}

impl Grating {
    /// Width of the stimulus, degrees (±3σ for a Gaussian window).
    pub fn extent(&self) -> f64 {
        match self.aperture {
            Aperture::Gauss { sigma } => 6.0 * sigma,
            Aperture::Square { side } => side,
            Aperture::Tapered { side } => side * 1.25,
            Aperture::Circle { radius } => 2.0 * radius,
        }
    }

    /// The window's value at (x, y) degrees from the centre.
    fn window(&self, x: f64, y: f64) -> f64 {
        match self.aperture {
            Aperture::Gauss { sigma } => (-(x * x + y * y) / (2.0 * sigma * sigma)).exp(),
            Aperture::Square { side } => f64::from(x.abs() <= side / 2.0 && y.abs() <= side / 2.0),
            Aperture::Tapered { side } => taper(x, side) * taper(y, side),
            Aperture::Circle { radius } => f64::from(x * x + y * y <= radius * radius),
        }
    }

    /// Whether the window has hard edges (antialiased by supersampling).
    fn hard(&self) -> bool {
        matches!(
            self.aperture,
            Aperture::Square { .. } | Aperture::Circle { .. }
        )
    }

    /// The pattern on a `side × side` raster at `ppd`, centred, row-major.
    pub fn raster(&self, ppd: f64, side: usize) -> Vec<f32> {
        let (sin, cos) = self.orientation.to_radians().sin_cos();
        let centre = side as f64 / 2.0;
        let mut out = Vec::with_capacity(side * side);
        for j in 0..side {
            for i in 0..side {
                let x = (i as f64 + 0.5 - centre) / ppd;
                let y = (centre - j as f64 - 0.5) / ppd;
                let carrier = (2.0 * PI * self.frequency * (x * cos + y * sin)).cos();
                let window = if self.hard() {
                    let mut sum = 0.0;
                    for sy in 0..4 {
                        for sx in 0..4 {
                            let dx = (sx as f64 - 1.5) / 4.0 / ppd;
                            let dy = (sy as f64 - 1.5) / 4.0 / ppd;
                            sum += self.window(x + dx, y + dy);
                        }
                    }
                    sum / 16.0
                } else {
                    self.window(x, y)
                };
                out.push((carrier * window) as f32);
            }
        }
        out
    }
}

/// A raised-cosine edge: 1 inside |t| ≤ side·3/8, 0 beyond side·5/8, ½ at side/2.
fn taper(t: f64, side: f64) -> f64 {
    let (inner, outer) = (side * 0.375, side * 0.625);
    let a = t.abs();
    if a <= inner {
        1.0
    } else if a >= outer {
        0.0
    } else {
        0.5 * (1.0 + (PI * (a - inner) / (outer - inner)).cos())
    }
}

/// Pixels per degree and raster side for a stimulus `extent` degrees wide with a carrier of
/// `frequency` cycles per degree; `None` when it cannot fit [`MAX_SIDE`] at
/// [`MIN_PX_PER_CYCLE`].
pub fn raster_for(extent: f64, frequency: f64) -> Option<(f64, usize)> {
    let side_at = |ppd: f64| (extent * ppd * FIELD).ceil() as usize + 2 * MARGIN_PX;
    let mut ppd = (PX_PER_CYCLE * frequency).max(MIN_PX_ACROSS / extent);
    if side_at(ppd) > MAX_SIDE {
        ppd = ((MAX_SIDE - 1 - 2 * MARGIN_PX) as f64 / (extent * FIELD)).floor();
        if ppd < MIN_PX_PER_CYCLE * frequency || ppd * extent < MIN_PX_ACROSS / 2.0 {
            return None;
        }
    }
    let side = side_at(ppd);
    // Odd, so that a pixel sits on the centre (the carrier's peak).
    Some((ppd, side | 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gabor_is_even_and_peaks_at_one_in_its_centre() {
        let g = Grating {
            frequency: 2.0,
            orientation: 0.0,
            aperture: Aperture::Gauss { sigma: 0.5 },
        };
        let (ppd, side) = raster_for(g.extent(), g.frequency).unwrap();
        let r = g.raster(ppd, side);
        let max = r.iter().fold(0f32, |m, v| m.max(v.abs()));
        assert!(max > 0.97 && max <= 1.0, "{max}");
        // Mirror symmetry about the centre (cosine phase).
        for j in 0..side {
            for i in 0..side {
                let a = r[j * side + i];
                let b = r[(side - 1 - j) * side + side - 1 - i];
                assert!((a - b).abs() < 1e-5);
            }
        }
        // Nearly zero at the raster's border.
        assert!(r[side / 2].abs() < 1e-3);
    }

    #[test]
    fn a_disc_has_its_area_and_the_raster_respects_its_limits() {
        let d = Grating {
            frequency: 0.0,
            orientation: 0.0,
            aperture: Aperture::Circle { radius: 1.0 },
        };
        let (ppd, side) = raster_for(d.extent(), 0.0).unwrap();
        let area: f64 = d.raster(ppd, side).iter().map(|&v| v as f64).sum::<f64>() / (ppd * ppd);
        assert!((area - PI).abs() < 0.01 * PI, "{area}");
        // 32 c/deg over 31 degrees cannot fit 1536 pixels at 3 pixels per cycle.
        assert_eq!(raster_for(31.0, 32.0), None);
        let (ppd, side) = raster_for(31.0, 0.125).unwrap();
        assert!(
            side <= MAX_SIDE && ppd * 31.0 >= MIN_PX_ACROSS,
            "{ppd} {side}"
        );
    }
}
