//! RGB triples: reflectance, exitance and irradiance all carry one value per channel.

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Sub};

use serde::{Deserialize, Serialize};

/// One value per colour channel, written as `[r, g, b]` in JSON.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(from = "[f64; 3]", into = "[f64; 3]")]
pub struct Rgb {
    /// Red.
    pub r: f64,
    /// Green.
    pub g: f64,
    /// Blue.
    pub b: f64,
}

impl Rgb {
    /// Zero in every channel: black, no light.
    pub const ZERO: Rgb = Rgb::splat(0.0);

    /// The triple `(r, g, b)`.
    pub const fn new(r: f64, g: f64, b: f64) -> Self {
        Rgb { r, g, b }
    }

    /// The same value in every channel: a grey.
    pub const fn splat(v: f64) -> Self {
        Rgb { r: v, g: v, b: v }
    }

    /// `[r, g, b]`.
    pub fn to_array(self) -> [f64; 3] {
        [self.r, self.g, self.b]
    }

    /// Mean of the three channels: the scalar used to order and compare powers.
    pub fn mean(self) -> f64 {
        (self.r + self.g + self.b) / 3.0
    }

    /// The largest channel.
    pub fn max_channel(self) -> f64 {
        self.r.max(self.g).max(self.b)
    }

    /// The smallest channel.
    pub fn min_channel(self) -> f64 {
        self.r.min(self.g).min(self.b)
    }

    /// Whether every channel is finite (neither NaN nor infinite).
    pub fn is_finite(self) -> bool {
        self.r.is_finite() && self.g.is_finite() && self.b.is_finite()
    }

    /// Whether every channel is exactly zero.
    pub fn is_zero(&self) -> bool {
        self.r == 0.0 && self.g == 0.0 && self.b == 0.0
    }

    /// Channel-wise product.
    pub fn mul_rgb(self, o: Rgb) -> Rgb {
        Rgb::new(self.r * o.r, self.g * o.g, self.b * o.b)
    }

    /// Channel-wise minimum.
    pub fn min(self, o: Rgb) -> Rgb {
        Rgb::new(self.r.min(o.r), self.g.min(o.g), self.b.min(o.b))
    }

    /// Channel-wise maximum.
    pub fn max(self, o: Rgb) -> Rgb {
        Rgb::new(self.r.max(o.r), self.g.max(o.g), self.b.max(o.b))
    }

    /// `f` applied to each channel.
    pub fn map(self, f: impl Fn(f64) -> f64) -> Rgb {
        Rgb::new(f(self.r), f(self.g), f(self.b))
    }
}

impl From<[f64; 3]> for Rgb {
    fn from(a: [f64; 3]) -> Self {
        Rgb::new(a[0], a[1], a[2])
    }
}

impl From<Rgb> for [f64; 3] {
    fn from(c: Rgb) -> Self {
        c.to_array()
    }
}

impl Add for Rgb {
    type Output = Rgb;
    fn add(self, o: Rgb) -> Rgb {
        Rgb::new(self.r + o.r, self.g + o.g, self.b + o.b)
    }
}

impl AddAssign for Rgb {
    fn add_assign(&mut self, o: Rgb) {
        *self = *self + o;
    }
}

impl Sub for Rgb {
    type Output = Rgb;
    fn sub(self, o: Rgb) -> Rgb {
        Rgb::new(self.r - o.r, self.g - o.g, self.b - o.b)
    }
}

impl Mul<f64> for Rgb {
    type Output = Rgb;
    fn mul(self, s: f64) -> Rgb {
        Rgb::new(self.r * s, self.g * s, self.b * s)
    }
}

impl MulAssign<f64> for Rgb {
    fn mul_assign(&mut self, s: f64) {
        *self = *self * s;
    }
}

impl Div<f64> for Rgb {
    type Output = Rgb;
    fn div(self, s: f64) -> Rgb {
        Rgb::new(self.r / s, self.g / s, self.b / s)
    }
}

impl std::iter::Sum for Rgb {
    fn sum<I: Iterator<Item = Rgb>>(iter: I) -> Rgb {
        iter.fold(Rgb::ZERO, Add::add)
    }
}
