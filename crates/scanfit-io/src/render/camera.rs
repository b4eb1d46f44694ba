//! The orthographic camera of the pictures: which world axis is up, the
//! named views, and the projection of points and normals.
//!
//! Pictures are composed in a z-up frame: the data are turned so that the
//! chosen up axis becomes z (a rotation, so nothing is mirrored), the
//! vertical exaggeration stretches that axis, and the camera looks from an
//! azimuth (around the up axis) and an elevation (above the plane across it).

use scanfit::{Point3, Vector3};

use super::RenderOptions;

/// The world axis that points up in a picture (the library's [`UpAxis`](scanfit::up_axis::UpAxis):
/// pictures are composed in its z-up frame).
pub use scanfit::up_axis::UpAxis as Up;

/// Named camera directions, relative to the up axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewPreset {
    /// From the front, level: azimuth -90, elevation 0 (z up: looking
    /// along +y with x to the right; y up: looking along -z).
    Front,
    /// From above: azimuth -90, elevation 90 (the horizontal axes as on a
    /// map: z up shows x to the right and y up).
    Top,
    /// An isometric view: azimuth -45, elevation 35.26 (atan(1/sqrt 2)), the
    /// three axes equally foreshortened.
    Iso,
}

impl ViewPreset {
    /// `(azimuth, elevation)` in degrees.
    pub fn angles(self) -> (f64, f64) {
        match self {
            ViewPreset::Front => (-90.0, 0.0),
            ViewPreset::Top => (-90.0, 90.0),
            ViewPreset::Iso => (-45.0, (0.5f64).sqrt().atan().to_degrees()),
        }
    }

    /// The preset named `name` (`front`, `top`, `iso`).
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "front" => Some(ViewPreset::Front),
            "top" => Some(ViewPreset::Top),
            "iso" => Some(ViewPreset::Iso),
            _ => None,
        }
    }
}

/// The orthographic camera of [`RenderOptions`]: projects world points to
/// `(right, up, towards the camera)` coordinates.
#[derive(Debug, Clone, Copy)]
pub struct Camera {
    /// The up axis.
    pub axis: Up,
    /// Vertical exaggeration (along the up axis).
    pub z_scale: f64,
    /// Image right, in the z-up frame.
    pub right: Vector3,
    /// Image up, in the z-up frame.
    pub up: Vector3,
    /// Towards the camera, in the z-up frame.
    pub toward: Vector3,
}

impl Camera {
    /// The camera of `opts` (a non-positive or non-finite `z_scale` counts as 1).
    pub fn new(opts: &RenderOptions) -> Self {
        let (az, el) = (opts.azimuth.to_radians(), opts.elevation.to_radians());
        let toward = Vector3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
        let right = Vector3::new(-az.sin(), az.cos(), 0.0);
        let up = toward.cross(&right);
        let z_scale = if opts.z_scale > 0.0 && opts.z_scale.is_finite() {
            opts.z_scale
        } else {
            1.0
        };
        Self {
            axis: opts.up,
            z_scale,
            right,
            up,
            toward,
        }
    }

    /// `p` in the exaggerated z-up frame.
    pub fn frame(&self, p: &Point3) -> Vector3 {
        let mut c = self.axis.to_frame(&p.coords);
        c.z *= self.z_scale;
        c
    }

    /// `(x right, y up, depth towards the camera)` of `p`.
    pub fn project(&self, p: &Point3) -> (f64, f64, f64) {
        let c = self.frame(p);
        (c.dot(&self.right), c.dot(&self.up), c.dot(&self.toward))
    }

    /// A surface normal `n` of the data as a normal of the exaggerated shape
    /// in the frame (normals transform with the inverse transpose).
    pub fn normal(&self, n: &Vector3) -> Vector3 {
        let mut m = self.axis.to_frame(n);
        m.z /= self.z_scale;
        m
    }

    /// The height of `p`: its coordinate along the up axis (unexaggerated).
    pub fn height(&self, p: &Point3) -> f64 {
        self.axis.height(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn up_frames_are_rotations() {
        let (a, b) = (Vector3::new(1.0, 2.0, 3.0), Vector3::new(-4.0, 0.5, 2.0));
        for up in [Up::X, Up::Y, Up::Z] {
            let (fa, fb) = (up.to_frame(&a), up.to_frame(&b));
            // lengths, angles and handedness kept
            assert_eq!(fa.norm(), a.norm());
            assert_eq!(fa.dot(&fb), a.dot(&b));
            assert_eq!(fa.cross(&fb), up.to_frame(&a.cross(&b)));
            // the up axis becomes z
            let p = Point3::from(a);
            assert_eq!(fa.z, up.height(&p));
        }
    }

    #[test]
    fn presets_look_where_they_say() {
        let opts = |v: ViewPreset, up: Up| {
            let (azimuth, elevation) = v.angles();
            Camera::new(&RenderOptions {
                azimuth,
                elevation,
                up,
                ..Default::default()
            })
        };
        let close = |a: Vector3, b: Vector3| (a - b).norm() < 1e-12;
        // y up, front: from +z, x right, y up (screen axes in world terms)
        let c = opts(ViewPreset::Front, Up::Y);
        let world = |v: Vector3| {
            // the frame is (x, -z, y): invert it
            Vector3::new(v.x, v.z, -v.y)
        };
        assert!(close(world(c.toward), Vector3::z()), "{:?}", c.toward);
        assert!(close(world(c.right), Vector3::x()));
        assert!(close(world(c.up), Vector3::y()));
        // z up, top: from +z, x right, y up
        let c = opts(ViewPreset::Top, Up::Z);
        assert!(close(c.toward, Vector3::z()));
        assert!(close(c.right, Vector3::x()));
        assert!(close(c.up, Vector3::y()));
        // iso: the three axes equally foreshortened
        let c = opts(ViewPreset::Iso, Up::Z);
        let f: Vec<f64> = [Vector3::x(), Vector3::y(), Vector3::z()]
            .iter()
            .map(|e| e.dot(&c.toward).abs())
            .collect();
        assert!(
            (f[0] - f[1]).abs() < 1e-12 && (f[1] - f[2]).abs() < 1e-12,
            "{f:?}"
        );
    }

    #[test]
    fn automatic_up_is_the_thin_axis_of_a_sheet_else_z() {
        let grid = |f: &dyn Fn(f64, f64, f64) -> Point3| -> Vec<Point3> {
            (0..2000)
                .map(|i| {
                    let (a, b) = ((i % 40) as f64, (i / 40) as f64);
                    f(a, b, ((i * 7) % 5) as f64)
                })
                .collect()
        };
        // a 40 x 50 sheet 5 thick across x, and a stray point far away
        let mut s = grid(&|a, b, t| Point3::new(t, a, b));
        s.push(Point3::new(1000.0, 0.0, 0.0));
        assert_eq!(Up::automatic(&s), Up::X);
        // a block 40 x 50 x 30 is no sheet: z
        let block = grid(&|a, b, t| Point3::new(a, b, 6.0 * t));
        assert_eq!(Up::automatic(&block), Up::Z);
    }
}
