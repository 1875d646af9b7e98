//! # A robot's captured frames as pictures
//!
//! A separate `impl Lab` block: a stored camera frame as grey bytes, as a
//! PNG, or as a small thumbnail for the page's film strip. A frame is its
//! pose and noise seed ([`crate::camera::capture`]); its pixels are made
//! again from those whenever they are asked for.

use super::Lab;
use crate::camera::CameraImage;
use image::ImageEncoder;

impl Lab {
    /// Robot `robot`'s captured frame `index`, grey, as the vision
    /// pipeline gets it.
    pub fn frame_grey(&self, robot: usize, index: usize) -> Result<CameraImage, String> {
        let f = self.frame(robot, index)?;
        self.frame_image(f)
    }

    /// The same frame as a PNG file (8-bit grey).
    pub fn frame_png(&self, robot: usize, index: usize) -> Result<Vec<u8>, String> {
        let img = self.frame_grey(robot, index)?;
        let mut out = Vec::new();
        image::codecs::png::PngEncoder::new(&mut out)
            .write_image(
                &img.gray,
                img.width,
                img.height,
                image::ExtendedColorType::L8,
            )
            .map_err(|e| e.to_string())?;
        Ok(out)
    }

    /// The frame as a thumbnail `width` pixels wide (1 … the camera's
    /// width; the height in proportion): the frame's pose rendered by a
    /// smaller camera with the same field of view
    /// ([`crate::camera::PinholeCamera::scaled`]), grey, without the pixel
    /// noise. The film strip's thumbnails, at a fraction of a frame's cost.
    pub fn frame_thumbnail(
        &self,
        robot: usize,
        index: usize,
        width: u32,
    ) -> Result<CameraImage, String> {
        let sim = self.simulation().ok_or("nothing has run yet")?;
        let f = self.frame(robot, index)?;
        if width == 0 || width > sim.camera.width {
            return Err(format!(
                "thumbnail width {width} must be 1 to the camera's {} pixels",
                sim.camera.width
            ));
        }
        let cam = sim.camera.scaled(width);
        Ok(crate::camera::render(
            &cam,
            &f.truth,
            &sim.world,
            &sim.scenario.walls,
            &f.others,
            &mut sim.textures.lock(),
            false,
            None,
        ))
    }
}
