//! The course's camera: an eye point and an image plane given by its four
//! corners; a pixel's sample points are bilinear in the corners, and the
//! pixel value is the filtered radiance through the pixel's square. How a
//! point of the plane becomes a ray is the camera's [`Projection`]: through
//! the eye (the course's pinhole), through a thin lens, or straight along
//! the view (orthographic).

use crate::filter::Filter;
use crate::math::{Direction, Ray, Vertex};
use crate::sampling::concentric_disk;
use glam::{Vec2, Vec3};

/// How the image plane's points become rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Every ray leaves the eye through its point of the plane (infinite
    /// depth of field).
    Pinhole,
    /// A thin lens of radius `radius` centred on the eye, in the plane
    /// parallel to the image plane; it brings the plane at distance `focus`
    /// (along the view axis) into focus. A ray leaves a point of the lens
    /// towards where the pinhole ray through its point of the plane meets
    /// the plane in focus, so points there are sharp and others blur into
    /// discs (Mitsuba 3's `thinlens`, src/sensors/thinlens.cpp; pbrt's
    /// thin-lens camera).
    ThinLens { radius: f32, focus: f32 },
    /// Every ray leaves its point of the plane along `dir`: the plane is the
    /// view's extent, the eye only its centre (Mitsuba 3's `orthographic`).
    Orthographic { dir: Direction },
}

impl Projection {
    /// Whether a ray needs a point of the lens as well as of the plane.
    pub fn has_lens(&self) -> bool {
        matches!(self, Projection::ThinLens { .. })
    }
}

#[derive(Clone, Copy, Debug)]
pub struct Camera {
    pub eye: Vertex,
    /// Corner at the top left of the written image.
    upper_left: Vertex,
    /// From the top-left to the top-right corner.
    across: Vec3,
    /// From the top-left to the bottom-left corner.
    down: Vec3,
    pub width: u32,
    pub height: u32,
    /// Whether the image plane may grow to another aspect ratio (a look-at
    /// camera's may; the course's four corners are the user's exact plane).
    pub widens: bool,
    /// Where a pixel's samples land about its centre (the course's box by
    /// default).
    pub filter: Filter,
    /// Rays start this far from the eye (or the lens) along the view axis
    /// (a near clip plane, as in Mitsuba's sensors); 0: at the eye. An
    /// orthographic camera's rays start on the image plane itself, and its
    /// near clip is where that plane is put.
    pub near: f32,
    pub projection: Projection,
}

impl Camera {
    /// `corners` in the course's order c1..c4 = (0,-1,-1), (0,1,-1), (0,1,1),
    /// (0,-1,1), i.e. lower-right, lower-left, upper-left, upper-right as seen
    /// from the eye (+y is to the left of the picture).
    pub fn from_corners(eye: Vertex, corners: [Vertex; 4], width: u32, height: u32) -> Self {
        // The lower-right corner is implied by the other three (a rectangle).
        let [_, lower_left, upper_left, upper_right] = corners;
        Camera {
            eye,
            upper_left,
            across: upper_right - upper_left,
            down: lower_left - upper_left,
            width,
            height,
            widens: false,
            filter: Filter::Box,
            near: 0.0,
            projection: Projection::Pinhole,
        }
    }

    /// A camera whose plane may widen to other aspect ratios ([`Self::fit`]).
    pub fn widening(mut self) -> Self {
        self.widens = true;
        self
    }

    /// The image plane's width over its height.
    pub fn aspect(&self) -> f32 {
        self.across.length() / self.down.length()
    }

    /// The camera at `width` x `height` pixels without stretching the
    /// picture: a plane of the same aspect takes the resolution as it is; a
    /// widening camera's plane grows about its centre along the side that
    /// the new aspect makes longer (the view only gains); a fixed plane of
    /// another aspect is refused, with the sizes that would fit.
    pub fn fit(self, width: u32, height: u32) -> Result<Camera, String> {
        let fitted = self.fit_plane(width, height)?;
        match fitted.precision_problem() {
            Some(problem) => Err(problem),
            None => Ok(fitted),
        }
    }

    fn fit_plane(self, width: u32, height: u32) -> Result<Camera, String> {
        let plane = self.aspect();
        // Within half a pixel of the plane's shape: the rounding of a size.
        let fits =
            (width as f32 - plane * height as f32).abs() <= 0.5 || (height as f32 - width as f32 / plane).abs() <= 0.5;
        if fits {
            return Ok(self.with_resolution(width, height));
        }
        if !self.widens {
            let h_for_w = (width as f32 / plane).round().max(1.0);
            let w_for_h = (plane * height as f32).round().max(1.0);
            return Err(format!(
                "{width}x{height} pixels would stretch the picture: the camera's image plane is {plane:.4}:1 \
                 (its four corners); give {width}x{h_for_w} or {w_for_h}x{height}, or move the corners \
                 (a look-at camera, with target, up and vfov, widens its view to any size)"
            ));
        }
        let wanted = width as f32 / height as f32;
        let mut c = self;
        if wanted > plane {
            let grow = wanted / plane;
            c.upper_left -= c.across * (grow - 1.0) * 0.5;
            c.across *= grow;
        } else {
            let grow = plane / wanted;
            c.upper_left -= c.down * (grow - 1.0) * 0.5;
            c.down *= grow;
        }
        Ok(c.with_resolution(width, height))
    }

    /// Why single precision cannot render this view, if it cannot: a
    /// pixel's ray direction is its plane point minus the eye, each rounded
    /// to the size of the larger coordinate, so far from the origin
    /// neighbouring pixels would get the same direction (an eye at 1e30
    /// sees one colour).
    pub fn precision_problem(&self) -> Option<String> {
        let spacing = (self.across.length() / self.width as f32).min(self.down.length() / self.height as f32);
        let corners = [self.upper_left, self.upper_left + self.across, self.upper_left + self.down];
        let scale = corners.iter().fold(self.eye.abs().max_element(), |m, c| m.max(c.abs().max_element()));
        // Rounding of half a pixel or more would move rays between pixels.
        let rounding = scale * f32::EPSILON;
        (!(spacing > 2.0 * rounding)).then(|| {
            format!(
                "the camera's coordinates (up to {scale:.3e}) are too large for single precision to tell its \
                 pixels apart ({spacing:.3e} apart on the image plane, rounding {rounding:.3e}); move the \
                 scene nearer the origin, or use fewer pixels"
            )
        })
    }

    /// The image plane: its top-left corner, and the vectors from there to
    /// the top-right and to the bottom-left corners.
    pub fn plane(&self) -> (Vertex, Vec3, Vec3) {
        (self.upper_left, self.across, self.down)
    }

    /// The same view at another resolution.
    pub fn with_resolution(mut self, width: u32, height: u32) -> Self {
        self.width = width;
        self.height = height;
        self
    }

    /// The same camera in a scene whose lengths are all multiplied by `s`.
    pub fn scaled(mut self, s: f32) -> Self {
        self.eye *= s;
        self.upper_left *= s;
        self.across *= s;
        self.down *= s;
        self.near *= s;
        if let Projection::ThinLens { radius, focus } = self.projection {
            self.projection = Projection::ThinLens { radius: radius * s, focus: focus * s };
        }
        self
    }

    /// The view axis: the image plane's unit normal, on the side away from
    /// the eye.
    pub fn axis(&self) -> Direction {
        let axis = self.across.cross(self.down).normalize();
        if axis.dot(self.upper_left - self.eye) < 0.0 {
            -axis
        } else {
            axis
        }
    }

    /// The ray through image position (`col` + u.x, `row` + u.y), row 0 at
    /// the top, through the lens's centre: the chief ray, which is the
    /// only ray of a camera without a lens.
    pub fn ray(&self, col: u32, row: u32, u: Vec2) -> Ray {
        self.sample_ray(col, row, u, Vec2::splat(0.5))
    }

    /// The ray through image position (`col` + u.x, `row` + u.y) and the
    /// point of the lens that `lens` in [0, 1)^2 picks, uniformly by area
    /// over the lens (ignored where the projection has none). The ray's
    /// direction is a unit vector.
    pub fn sample_ray(&self, col: u32, row: u32, u: Vec2, lens: Vec2) -> Ray {
        let u = self.filter.place(u);
        let fx = (col as f32 + u.x) / self.width as f32;
        let fy = (row as f32 + u.y) / self.height as f32;
        let p = self.upper_left + fx * self.across + fy * self.down;
        match self.projection {
            Projection::Pinhole => {
                let dir = (p - self.eye).normalize();
                if self.near > 0.0 {
                    return Ray::new(self.eye + dir * (self.near / dir.dot(self.axis())), dir);
                }
                Ray::new(self.eye, dir)
            }
            Projection::ThinLens { radius, focus } => {
                let axis = self.axis();
                let through = p - self.eye;
                let in_focus = self.eye + through * (focus / through.dot(axis));
                let d = concentric_disk(lens) * radius;
                let on_lens = self.eye + d.x * self.across.normalize() + d.y * self.down.normalize();
                let dir = (in_focus - on_lens).normalize();
                Ray::new(on_lens + dir * (self.near / dir.dot(axis)), dir)
            }
            Projection::Orthographic { dir } => Ray::new(p, dir),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::sampling::{next_2d, stream, Domain};
    use crate::scene::{Eye, Scene};
    use glam::{Vec2, Vec3};

    #[test]
    fn a_camera_far_from_the_origin_is_a_precision_problem() {
        let cam = Scene::tncg15(Eye::One).camera;
        assert!(cam.precision_problem().is_none());
        assert!(cam.with_resolution(65536, 65536).precision_problem().is_none());
        let far =
            super::Camera { eye: cam.eye + Vec3::splat(1e7), upper_left: cam.upper_left + Vec3::splat(1e7), ..cam };
        assert!(far.precision_problem().unwrap().contains("too large for single precision"));
    }

    #[test]
    fn pixel_centres_follow_the_course_formula() {
        let cam = Scene::tncg15(Eye::One).camera;
        // Course pixel (i, j) has centre (0, i*0.0025 - 0.99875, j*0.0025 - 0.99875);
        // the written column is 799 - i and the row is 799 - j.
        for (i, j) in [(0u32, 0u32), (799, 799), (123, 456)] {
            let r = cam.ray(799 - i, 799 - j, Vec2::splat(0.5));
            let t = (0.0 - r.origin.x) / r.dir.x;
            let p = r.at(t);
            let want = Vec3::new(0.0, i as f32 * 0.0025 - 0.99875, j as f32 * 0.0025 - 0.99875);
            assert!((p - want).length() < 1e-5, "{p} vs {want}");
        }
        // Field of view: the top edge's centre seen from e1 at 2*atan(1/2).
        let top = cam.ray(400, 0, Vec2::new(0.0, 0.0));
        let bottom = cam.ray(400, 799, Vec2::new(0.0, 1.0));
        let fov = top.dir.angle_between(bottom.dir).to_degrees();
        assert!((fov - 53.130).abs() < 0.01, "{fov}");
        let cam2 = Scene::tncg15(Eye::Two).camera;
        let fov2 = cam2.ray(400, 0, Vec2::ZERO).dir.angle_between(cam2.ray(400, 799, Vec2::new(0.0, 1.0)).dir);
        assert!((fov2.to_degrees() - 90.0).abs() < 0.01);
    }

    /// Other image sizes keep the picture's proportions: a widening camera
    /// gains view along the longer side (the original view stays in the
    /// middle, at the same scale); a fixed plane of another shape is
    /// refused with the sizes that fit.
    #[test]
    fn other_sizes_keep_the_aspect() {
        let square = Scene::tncg15(Eye::One).camera;
        let wide = square.widening().fit(400, 200).unwrap();
        let (_, across, down) = wide.plane();
        assert!((across.length() / down.length() - 2.0).abs() < 1e-5);
        // Pixels stay square: the same angle a pixel across and down.
        let (a, b, c) =
            (wide.ray(200, 100, Vec2::ZERO), wide.ray(201, 100, Vec2::ZERO), wide.ray(200, 101, Vec2::ZERO));
        let (h, v) = (a.dir.angle_between(b.dir), a.dir.angle_between(c.dir));
        assert!((h / v - 1.0).abs() < 1e-3, "{h} vs {v}");
        // The centre ray and the vertical field of view are unchanged.
        let centre = square.ray(400, 400, Vec2::ZERO).dir;
        assert!(wide.ray(200, 100, Vec2::ZERO).dir.angle_between(centre) < 1e-5);
        let fov = wide.ray(200, 0, Vec2::ZERO).dir.angle_between(wide.ray(200, 199, Vec2::new(0.0, 1.0)).dir);
        assert!((fov.to_degrees() - 53.130).abs() < 0.01);
        let tall = square.widening().fit(100, 300).unwrap();
        let (_, across, down) = tall.plane();
        assert!((down.length() / across.length() - 3.0).abs() < 1e-5);
        // The same shape at another size, and a fixed plane refused.
        assert!(square.fit(160, 160).is_ok());
        let err = square.fit(400, 200).unwrap_err();
        assert!(err.contains("400x400 or 200x200"), "{err}");
    }

    /// A camera 1 from a 2 x 2 plane (90° across), looking along +z.
    fn square(projection: super::Projection) -> super::Camera {
        let c = [
            Vec3::new(1.0, -1.0, 1.0),
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(-1.0, 1.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
        ];
        super::Camera { projection, ..super::Camera::from_corners(Vec3::ZERO, c, 64, 64) }
    }

    /// Through a thin lens every ray of an image point passes through one
    /// point of the plane in focus: the pinhole ray's point there. Its
    /// chief ray is the pinhole's.
    #[test]
    fn thin_lens_rays_meet_in_the_plane_in_focus() {
        use super::Projection;
        let lens = square(Projection::ThinLens { radius: 0.3, focus: 4.0 });
        let pinhole = square(Projection::Pinhole);
        let mut rng = stream(3, Domain::Camera, 0);
        for (col, row) in [(0u32, 0u32), (31, 40), (63, 5)] {
            let u = next_2d(&mut rng);
            let chief = pinhole.ray(col, row, u);
            assert!((lens.ray(col, row, u).dir - chief.dir).length() < 1e-6);
            let want = chief.at(4.0 / chief.dir.z);
            let mut spread = 0.0f32;
            for _ in 0..64 {
                let r = lens.sample_ray(col, row, u, next_2d(&mut rng));
                assert!(r.origin.z.abs() < 1e-6 && r.origin.truncate().length() <= 0.3 + 1e-6, "{}", r.origin);
                assert!((r.dir.length() - 1.0).abs() < 1e-6);
                let at = r.at((4.0 - r.origin.z) / r.dir.z);
                assert!((at - want).length() < 1e-5, "{at} vs {want}");
                spread = spread.max(r.origin.length());
            }
            assert!(spread > 0.2, "the lens is used: {spread}");
        }
        // A near clip moves the origins onto the plane z = near.
        let near = super::Camera { near: 0.5, ..lens };
        let r = near.sample_ray(10, 20, Vec2::splat(0.3), Vec2::new(0.9, 0.1));
        assert!((r.origin.z - 0.5).abs() < 1e-6, "{}", r.origin);
        // The same rays in a scene twice the size: lens and focus scale too.
        let (a, b) = (
            lens.sample_ray(5, 6, Vec2::splat(0.5), Vec2::new(0.2, 0.7)),
            lens.scaled(2.0).sample_ray(5, 6, Vec2::splat(0.5), Vec2::new(0.2, 0.7)),
        );
        assert!((b.origin - 2.0 * a.origin).length() < 1e-5 && (b.dir - a.dir).length() < 1e-6);
    }

    /// Lens points are uniform by area over the lens: chi-square over 10 x
    /// 10 cells equal in area (r^2 and angle).
    #[test]
    fn lens_points_are_uniform_on_the_lens() {
        use super::Projection;
        let lens = square(Projection::ThinLens { radius: 0.25, focus: 3.0 });
        let mut rng = stream(7, Domain::Camera, 1);
        let mut counts = [0u32; 100];
        let n = 100_000;
        for _ in 0..n {
            let o = lens.sample_ray(20, 30, next_2d(&mut rng), next_2d(&mut rng)).origin / 0.25;
            let a = ((o.x * o.x + o.y * o.y) * 10.0).min(9.999) as usize;
            let b =
                ((o.y.atan2(o.x).rem_euclid(std::f32::consts::TAU) / std::f32::consts::TAU) * 10.0).min(9.999) as usize;
            counts[a * 10 + b] += 1;
        }
        let expected = n as f64 / 100.0;
        let chi2: f64 = counts.iter().map(|&c| (c as f64 - expected).powi(2) / expected).sum();
        // 99 degrees of freedom: p = 0.001 at 148.2.
        assert!(chi2 < 148.2, "chi2 = {chi2}");
    }

    /// Orthographic rays are parallel and start on the plane, at the
    /// pixel's point of it.
    #[test]
    fn orthographic_rays_start_on_the_plane() {
        let dir = Vec3::new(0.0, 0.6, 0.8);
        let ortho = square(super::Projection::Orthographic { dir });
        for (col, row, u) in [(0u32, 0u32, Vec2::ZERO), (63, 63, Vec2::ONE), (16, 48, Vec2::splat(0.5))] {
            let r = ortho.sample_ray(col, row, u, Vec2::new(0.9, 0.2));
            let want = Vec3::new(2.0 * (col as f32 + u.x) / 64.0 - 1.0, 1.0 - 2.0 * (row as f32 + u.y) / 64.0, 1.0);
            assert!((r.origin - want).length() < 1e-6, "{} vs {want}", r.origin);
            assert_eq!(r.dir, dir);
        }
        assert!(!super::Projection::Orthographic { dir }.has_lens());
    }
}
