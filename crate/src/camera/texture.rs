//! # Wall textures: procedural, deterministic, rich in features
//!
//! A camera that sees blank walls gives SURF nothing to match (thesis §5.2:
//! features are blobs and corners). Every wall face therefore carries a
//! texture: a picture painted on a strip `wall_height_m` tall that runs along
//! the wall. Textures are **generated**, never stored: the picture is a
//! function of the texture's name, the scenario's seed and the position
//! along the wall, so walls with the same name look alike and any run can be
//! reproduced exactly.
//!
//! The strip is cut into 1 m *chunks*. Chunk `k` of a texture is painted with
//! tiny-skia from shapes seeded by `(name, seed, k)`; shapes may reach into
//! the neighbouring chunks, so each chunk also paints the shapes of chunks
//! `k − 1` and `k + 1`, and the seams are invisible. Chunks are rasterised on
//! first use at [`TEXELS_PER_M`] with two coarser mip levels (for distant
//! walls, where sampling the full-resolution texture would alias into false
//! features) and cached, within a bounded cache.
//!
//! Styles give names their look: `brick` (bricks with stains and posters),
//! `posters` (framed rectangles with blobs and text lines), `signs` (discs,
//! triangles and arrows), `graffiti` (overlapping blobs and strokes),
//! `tiles`, `wood`, `marble`, `bookshelf`, `crates`, `maps`, `mosaic`,
//! `stone`. Any other name picks a style and its parameters from its hash,
//! so different names look clearly different. Reserved: **`plain`**, an even
//! featureless wall (nothing for SURF to find, on purpose), and `image:NAME`,
//! a picture the user loaded (see [`ImageTexture`]).

use crate::palette::{hsl_to_rgb, name_hash};
use crate::rng::Rng;
use std::collections::HashMap;
use std::sync::Arc;
use tiny_skia::{Color, FillRule, Paint, Path, PathBuilder, Pixmap, Rect, Stroke, Transform};

/// Texture resolution (texels per metre).
///
/// (A chunk's colour, four bytes a texel, is three quarters of its bytes
/// and only the page's colour views read it: the cache keeps it only for
/// chunks a colour view asked for, [`TextureBank::chunk_for`]; a grey one
/// asked for colour later is painted again, identically.)
pub const TEXELS_PER_M: u32 = 160;
/// Most chunks kept in the cache at once (each about 100 KB with its mips).
pub const CHUNK_CACHE_CAP: usize = 600;
/// Largest picture a user may load (pixels on a side, and in all).
pub const MAX_IMAGE_SIDE: u32 = 4096;
pub const MAX_IMAGE_PIXELS: u64 = 16_000_000;

/// Whether a shape with bounds `b`, drawn translated by `t` and padded by
/// `pad` texels, reaches into `pm` at all. A chunk paints its neighbours'
/// shapes too, and most of those lie wholly outside it; tiny-skia would
/// draw nothing for them but only after setting up a blitter, which costs
/// more than most shapes' pixels. Culled here instead, after the shape's
/// random draws (its colour is an argument), so no texture changes.
fn reaches(pm: &Pixmap, b: Rect, t: Transform, pad: f32) -> bool {
    let (x0, x1) = (b.left() + t.tx - pad, b.right() + t.tx + pad);
    let (y0, y1) = (b.top() + t.ty - pad, b.bottom() + t.ty + pad);
    x1 >= 0.0 && y1 >= 0.0 && x0 <= pm.width() as f32 && y0 <= pm.height() as f32
}

fn fill_path(pm: &mut Pixmap, path: &Path, paint: &Paint, rule: FillRule, t: Transform) {
    if reaches(pm, path.bounds(), t, 1.0) {
        pm.fill_path(path, paint, rule, t, None);
    }
}

fn fill_rect(pm: &mut Pixmap, rect: Rect, paint: &Paint, t: Transform) {
    if reaches(pm, rect, t, 1.0) {
        pm.fill_rect(rect, paint, t, None);
    }
}

fn stroke_path(pm: &mut Pixmap, path: &Path, paint: &Paint, stroke: &Stroke, t: Transform) {
    // Joins and caps reach beyond the path by up to a few widths.
    if reaches(pm, path.bounds(), t, 4.0 * stroke.width + 1.0) {
        pm.stroke_path(path, paint, stroke, t, None);
    }
}

/// The look of a texture family.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    Plain,
    Brick,
    Posters,
    Signs,
    Graffiti,
    Tiles,
    Wood,
    Marble,
}

const STYLES: [Style; 7] = [
    Style::Brick,
    Style::Posters,
    Style::Signs,
    Style::Graffiti,
    Style::Tiles,
    Style::Wood,
    Style::Marble,
];

impl Style {
    /// The style a texture name gets.
    pub fn for_name(name: &str) -> Style {
        match name {
            "plain" => Style::Plain,
            "brick" | "stone" => Style::Brick,
            "posters" | "maps" | "bookshelf" => Style::Posters,
            "signs" | "crates" => Style::Signs,
            "graffiti" | "mosaic" => Style::Graffiti,
            "tiles" => Style::Tiles,
            "wood" => Style::Wood,
            "marble" => Style::Marble,
            other => STYLES[(name_hash(other) % STYLES.len() as u64) as usize],
        }
    }
}

/// Which texture a wall face shows: its name (or a per-wall name), and the
/// face (the back of a wall gets its own variant, so the two sides of a thin
/// wall never look alike).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct TextureKey {
    pub name: String,
    pub back: bool,
    /// Texels of each chunk actually painted, from its left edge:
    /// [`TEXELS_PER_M`] for whole chunks. A wall shorter than a chunk that
    /// alone shows its texture (an unnamed wall) needs only its own length:
    /// a floor plan traced as thousands of short segments would otherwise
    /// paint a whole metre of texture for each centimetre of wall. The
    /// texels painted are the same either way, up to a few texels at shape
    /// edges that the narrower pixmap cuts (`tests/camera.rs`).
    pub width: u32,
}

impl TextureKey {
    /// A texture's key, with whole chunks.
    pub fn new(name: impl Into<String>, back: bool) -> TextureKey {
        TextureKey {
            name: name.into(),
            back,
            width: TEXELS_PER_M,
        }
    }

    /// Chunks painted only as wide as a wall of `length_m` needs, with room
    /// for the renderer's bilinear footprint at the coarsest mip level, and
    /// a multiple of 4 so the mips halve evenly.
    pub fn for_length(mut self, length_m: f64) -> TextureKey {
        let needed = (length_m.max(0.0) * TEXELS_PER_M as f64).ceil() + 8.0;
        if needed < TEXELS_PER_M as f64 {
            self.width = ((needed as u32).div_ceil(4) * 4).min(TEXELS_PER_M);
        }
        self
    }
}

/// One rasterised chunk: grayscale at three mip levels, and colour at full
/// resolution for display (empty unless asked for).
pub struct Chunk {
    /// `gray[l]` is `(TEXELS_PER_M >> l) × (height >> l)` texels, row 0 at the top.
    pub gray: [Vec<u8>; 3],
    pub rgba: Vec<u8>,
    pub width: [u32; 3],
    pub height: [u32; 3],
}

/// A picture the user loaded, to be put on walls named `image:NAME`.
#[derive(Clone, Debug)]
pub struct ImageTexture {
    pub width: u32,
    pub height: u32,
    /// Straight RGBA.
    pub rgba: Vec<u8>,
}

impl ImageTexture {
    /// Decodes a PNG or JPEG. Refuses empty, undecodable and oversized images
    /// with a message.
    pub fn decode(bytes: &[u8]) -> Result<ImageTexture, String> {
        if bytes.is_empty() {
            return Err("the image file is empty".into());
        }
        let format =
            image::guess_format(bytes).map_err(|_| "not a PNG or JPEG image".to_string())?;
        if !matches!(format, image::ImageFormat::Png | image::ImageFormat::Jpeg) {
            return Err(format!(
                "{format:?} images are not supported: use PNG or JPEG"
            ));
        }
        let reader = image::ImageReader::with_format(std::io::Cursor::new(bytes), format);
        let (w, h) = reader
            .into_dimensions()
            .map_err(|e| format!("cannot read the image: {e}"))?;
        if w == 0
            || h == 0
            || w > MAX_IMAGE_SIDE
            || h > MAX_IMAGE_SIDE
            || (w as u64) * (h as u64) > MAX_IMAGE_PIXELS
        {
            return Err(format!(
                "the image is {w}x{h}: at most {MAX_IMAGE_SIDE} px on a side and {MAX_IMAGE_PIXELS} px in all"
            ));
        }
        let img = image::load_from_memory_with_format(bytes, format)
            .map_err(|e| format!("cannot decode the image: {e}"))?
            .to_rgba8();
        Ok(ImageTexture {
            width: img.width(),
            height: img.height(),
            rgba: img.into_raw(),
        })
    }
}

/// Generates and caches texture chunks.
pub struct TextureBank {
    seed: u64,
    wall_height_m: f64,
    /// Each chunk with the tick of its last use: at the cap the least
    /// recently used goes. (Evicting the oldest instead thrashes when one
    /// frame needs hundreds of chunks, as a wall traced as many short
    /// segments does: each frame would repaint what the last one evicted.)
    chunks: HashMap<(TextureKey, i64), (Arc<Chunk>, u64)>,
    tick: u64,
    images: HashMap<String, ImageTexture>,
}

/// A solid paint, **not anti-aliased**. A texture is the wall itself, not
/// a picture of it: its shapes may have hard, pixel-stepped edges like a
/// tiled mosaic, and both robots see the same steps. What must not alias is
/// the *camera's* sampling of the texture, and that is the mip levels' and
/// bilinear filtering's job at render time. Anti-aliased filling (tiny-skia
/// covers each pixel row with four sub-scanlines) cost half of all
/// painting, and painting was the largest part of describing a run's
/// frames (docs/history/issue-6-map-merging.md, round 8).
fn rgb(c: [u8; 3], a: u8) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(Color::from_rgba8(c[0], c[1], c[2], a));
    p.anti_alias = false;
    p
}

fn luma(r: u8, g: u8, b: u8) -> u8 {
    ((77 * r as u32 + 150 * g as u32 + 29 * b as u32) >> 8) as u8
}

/// A random colour from a palette anchored on `base_hue`.
fn colour(rng: &mut Rng, base_hue: f64, spread: f64) -> [u8; 3] {
    let h = (base_hue + rng.range(-spread, spread)).rem_euclid(360.0);
    let s = rng.range(0.25, 0.85);
    let l = rng.range(0.12, 0.88);
    hsl_to_rgb(h, s, l)
}

impl Clone for TextureBank {
    /// A clone shares the seed and the loaded pictures; its chunk cache starts
    /// empty (chunks are regenerated identically on demand).
    fn clone(&self) -> Self {
        TextureBank {
            seed: self.seed,
            wall_height_m: self.wall_height_m,
            chunks: HashMap::new(),
            tick: 0,
            images: self.images.clone(),
        }
    }
}

impl std::fmt::Debug for TextureBank {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TextureBank")
            .field("seed", &self.seed)
            .field("cached_chunks", &self.chunks.len())
            .field("images", &self.images.keys().collect::<Vec<_>>())
            .finish()
    }
}

impl TextureBank {
    pub fn new(seed: u64, wall_height_m: f64) -> Self {
        TextureBank {
            seed,
            wall_height_m,
            chunks: HashMap::new(),
            tick: 0,
            images: HashMap::new(),
        }
    }

    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Bytes held by the cached chunks and the loaded pictures.
    pub fn memory_bytes(&self) -> usize {
        let chunks: usize = self
            .chunks
            .values()
            .map(|(c, _)| c.gray.iter().map(Vec::capacity).sum::<usize>() + c.rgba.capacity())
            .sum();
        chunks
            + self
                .images
                .values()
                .map(|i| i.rgba.capacity())
                .sum::<usize>()
    }

    pub fn wall_height_m(&self) -> f64 {
        self.wall_height_m
    }

    /// A fresh bank for another seed or wall height, keeping the pictures.
    pub fn renewed(self, seed: u64, wall_height_m: f64) -> TextureBank {
        TextureBank {
            images: self.images,
            ..TextureBank::new(seed, wall_height_m)
        }
    }

    /// Makes `image:NAME` walls show this picture.
    pub fn add_image(&mut self, name: &str, image: ImageTexture) {
        self.images.insert(name.to_string(), image);
        self.chunks
            .retain(|(k, _), _| k.name != format!("image:{name}"));
    }

    pub fn has_image(&self, name: &str) -> bool {
        self.images.contains_key(name)
    }

    /// Chunks currently cached.
    pub fn cached_chunks(&self) -> usize {
        self.chunks.len()
    }

    /// The chunk `k` of a texture, generating it on first use. Shared, so a
    /// renderer can hold on to the chunk it is drawing from column after
    /// column without looking it up again.
    pub fn chunk(&mut self, key: &TextureKey, k: i64) -> Arc<Chunk> {
        self.chunk_for(key, k, true)
    }

    /// Chunk `k` of texture `key`, with its colour only if `colour` (see
    /// [`TEXELS_PER_M`]'s note): the grey levels are the same either way.
    pub fn chunk_for(&mut self, key: &TextureKey, k: i64, colour: bool) -> Arc<Chunk> {
        self.tick += 1;
        let id = (key.clone(), k);
        if let Some((c, used)) = self.chunks.get_mut(&id) {
            if !colour || !c.rgba.is_empty() {
                *used = self.tick;
                return c.clone();
            }
            // Grey only, and colour wanted: painted again below.
            self.chunks.remove(&id);
        }
        if self.chunks.len() >= CHUNK_CACHE_CAP {
            // A scan of the cap's entries, against painting a chunk (~1 ms).
            let oldest = self
                .chunks
                .iter()
                .min_by_key(|(_, (_, used))| *used)
                .map(|(id, _)| id.clone());
            if let Some(old) = oldest {
                self.chunks.remove(&old);
            }
        }
        let mut painted = self.paint_chunk(key, k);
        if !colour {
            painted.rgba = Vec::new();
        }
        let chunk = Arc::new(painted);
        self.chunks.insert(id, (chunk.clone(), self.tick));
        chunk
    }

    fn paint_chunk(&self, key: &TextureKey, k: i64) -> Chunk {
        // Shapes are laid out on whole chunks; the pixmap may be narrower.
        let w = TEXELS_PER_M;
        let h = ((self.wall_height_m * TEXELS_PER_M as f64).round() as u32).max(4);
        let painted = key.width.clamp(4, TEXELS_PER_M);
        let mut pm = match Pixmap::new(painted, h) {
            Some(p) => p,
            None => return Self::flat_chunk(painted, h, 128),
        };
        if let Some(img) = key
            .name
            .strip_prefix("image:")
            .and_then(|n| self.images.get(n))
        {
            Self::paint_image(&mut pm, img, k);
        } else {
            let style = Style::for_name(&key.name);
            let family = name_hash(&key.name)
                ^ self.seed.wrapping_mul(0x9E37_79B9_7F4A_7C15)
                ^ if key.back { 0x5555 } else { 0 };
            let mut base = Rng::new(family);
            let hue = base.range(0.0, 360.0);
            let bg = colour(&mut base, hue, 20.0);
            // Sizes of the regular grids (bricks, tiles, planks): one per
            // texture, so that the grid runs on unbroken across chunks.
            let grid = [
                base.range(0.07, 0.11),
                base.range(2.0, 3.2),
                base.range(0.12, 0.25),
                base.range(0.1, 0.2),
            ];
            pm.fill(Color::from_rgba8(bg[0], bg[1], bg[2], 255));
            if style != Style::Plain {
                for dk in -1..=1 {
                    let mut rng = Rng::new(
                        family
                            ^ 0xC1A7_7E55
                            ^ ((k + dk) as u64).wrapping_mul(0x9FB2_1C65_1E98_DF25),
                    );
                    Self::paint_clutter(&mut pm, &mut rng, hue, dk as f32 * w as f32);
                }
                for dk in -1..=1 {
                    let mut rng =
                        Rng::new(family ^ ((k + dk) as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
                    self.paint_shapes(
                        &mut pm,
                        style,
                        &mut rng,
                        hue,
                        &grid,
                        k + dk,
                        dk as f32 * w as f32,
                    );
                }
            } else {
                let g = luma(bg[0], bg[1], bg[2]);
                pm.fill(Color::from_rgba8(g, g, g, 255));
            }
        }
        Self::from_pixmap(pm)
    }

    fn flat_chunk(w: u32, h: u32, g: u8) -> Chunk {
        let gray0 = vec![g; (w * h) as usize];
        let (w1, h1, w2, h2) = (w / 2, h / 2, w / 4, h / 4);
        Chunk {
            gray: [
                gray0,
                vec![g; (w1 * h1) as usize],
                vec![g; (w2 * h2) as usize],
            ],
            rgba: [g, g, g, 255].repeat((w * h) as usize),
            width: [w, w1, w2],
            height: [h, h1, h2],
        }
    }

    fn from_pixmap(pm: Pixmap) -> Chunk {
        let (w, h) = (pm.width(), pm.height());
        // Opaque, so premultiplied bytes are straight RGBA: kept as they are.
        let rgba = pm.take();
        let gray0: Vec<u8> = rgba
            .chunks_exact(4)
            .map(|p| luma(p[0], p[1], p[2]))
            .collect();
        let half = |src: &[u8], sw: u32, sh: u32| {
            let (dw, dh) = (sw / 2, sh / 2);
            let mut out = vec![0u8; (dw * dh) as usize];
            for y in 0..dh {
                for x in 0..dw {
                    let i = (2 * y * sw + 2 * x) as usize;
                    let s = src[i] as u32
                        + src[i + 1] as u32
                        + src[i + sw as usize] as u32
                        + src[i + sw as usize + 1] as u32;
                    out[(y * dw + x) as usize] = ((s + 2) / 4) as u8;
                }
            }
            out
        };
        let gray1 = half(&gray0, w, h);
        let gray2 = half(&gray1, w / 2, h / 2);
        Chunk {
            gray: [gray0, gray1, gray2],
            rgba,
            width: [w, w / 2, w / 4],
            height: [h, h / 2, h / 4],
        }
    }

    /// A user picture spans the wall's height; its width keeps the aspect
    /// ratio and it repeats along the wall.
    fn paint_image(pm: &mut Pixmap, img: &ImageTexture, k: i64) {
        let (w, h) = (pm.width(), pm.height());
        let img_w_texels = (img.width as f64 * h as f64 / img.height as f64).max(1.0);
        let data = pm.data_mut();
        for y in 0..h {
            let sy = ((y as f64 + 0.5) * img.height as f64 / h as f64) as u32;
            for x in 0..w {
                let u = (k as f64 * TEXELS_PER_M as f64 + x as f64 + 0.5).rem_euclid(img_w_texels);
                let sx = ((u / img_w_texels) * img.width as f64) as u32;
                let s = ((sy.min(img.height - 1) * img.width + sx.min(img.width - 1)) * 4) as usize;
                let d = ((y * w + x) * 4) as usize;
                data[d..d + 3].copy_from_slice(&img.rgba[s..s + 3]);
                data[d + 3] = 255;
            }
        }
    }

    /// Wear and tear under every style: stains and specks at several scales
    /// (2 to 12 cm), so that even the plain stretches between a style's
    /// shapes carry blobs for a detector to find at any distance.
    fn paint_clutter(pm: &mut Pixmap, rng: &mut Rng, hue: f64, x0: f32) {
        let w = TEXELS_PER_M as f64;
        let h = pm.height() as f64;
        let t = Transform::from_translate(x0, 0.0);
        let n = rng.range(45.0, 70.0) as usize;
        for i in 0..n {
            // Sizes spread geometrically: many small specks, a few stains.
            let r = 3.0 * 2f64.powf(rng.range(0.0, 2.0 + 2.0 * (i % 3) as f64 / 2.0));
            let (cx, cy) = (rng.range(0.0, w), rng.range(0.0, h));
            let c = colour(rng, hue + 180.0 * (i % 2) as f64, 60.0);
            let a = rng.range(120.0, 255.0) as u8;
            let mut pb = PathBuilder::new();
            if i % 4 == 3 {
                // A few hard-edged marks for corners.
                if let Some(rc) = Rect::from_xywh(cx as f32, cy as f32, (1.4 * r) as f32, r as f32)
                {
                    pb.push_rect(rc);
                }
            } else {
                pb.push_oval(
                    match Rect::from_xywh(
                        cx as f32,
                        cy as f32,
                        (2.0 * r) as f32,
                        (1.2 * r + rng.range(0.0, r)) as f32,
                    ) {
                        Some(rc) => rc,
                        None => continue,
                    },
                );
            }
            if let Some(p) = pb.finish() {
                fill_path(pm, &p, &rgb(c, a), FillRule::Winding, t);
            }
        }
    }

    /// Paints the shapes that belong to chunk `kk` (their left edges or
    /// centres fall in it), drawn shifted by `x0` texels. `grid` holds the
    /// texture's brick height, brick aspect, tile size and plank width.
    #[allow(clippy::too_many_arguments)]
    fn paint_shapes(
        &self,
        pm: &mut Pixmap,
        style: Style,
        rng: &mut Rng,
        hue: f64,
        grid: &[f64; 4],
        kk: i64,
        x0: f32,
    ) {
        let at = Placement {
            w: TEXELS_PER_M as f32,
            h: pm.height() as f32,
            t: Transform::from_translate(x0, 0.0),
            kk,
        };
        match style {
            Style::Plain => {}
            Style::Brick => self.paint_bricks(pm, rng, hue, grid, &at),
            Style::Posters => self.paint_posters(pm, rng, hue, &at),
            Style::Signs => paint_signs(pm, rng, hue, &at),
            Style::Graffiti => paint_graffiti(pm, rng, hue, &at),
            Style::Tiles => paint_tiles(pm, rng, hue, grid, &at),
            Style::Wood => paint_wood(pm, rng, hue, grid, &at),
            Style::Marble => paint_marble(pm, rng, hue, &at),
        }
    }

    /// `brick`: rows of bricks laid along the whole wall, stains, and
    /// sometimes a poster.
    fn paint_bricks(
        &self,
        pm: &mut Pixmap,
        rng: &mut Rng,
        hue: f64,
        grid: &[f64; 4],
        at: &Placement,
    ) {
        let (w, h, t) = (at.w, at.h, at.t);
        let kk = at.kk;
        let bh = grid[0] as f32 * w;
        let bw = bh * grid[1] as f32;
        let rows = (h / bh) as i32 + 1;
        // Bricks are laid in rows along the whole wall; the chunk owns
        // the bricks whose left edge (in wall coordinates) is in it.
        let chunk_left = kk as f32 * w;
        for r in 0..rows {
            let off = if r % 2 == 0 { 0.0 } else { bw / 2.0 };
            let first = ((chunk_left - off) / bw).ceil() as i64;
            let mut j = first;
            loop {
                let x = off + j as f32 * bw - chunk_left;
                if x >= w {
                    break;
                }
                let c = colour(rng, hue, 25.0);
                if let Some(rc) = texel_rect(x + 1.5, r as f32 * bh + 1.5, bw - 3.0, bh - 3.0) {
                    fill_rect(pm, rc, &rgb(c, 255), t);
                }
                j += 1;
            }
        }
        // Stains and a few posters.
        for _ in 0..rng.range(2.0, 6.0) as usize {
            let (cx, cy) = (
                rng.range(0.0, w as f64) as f32,
                rng.range(0.0, h as f64) as f32,
            );
            if let Some(p) = {
                let radius = rng.range(6.0, 30.0) as f32;
                blob(rng, cx, cy, radius)
            } {
                let c = colour(rng, hue + 90.0, 120.0);
                fill_path(pm, &p, &rgb(c, 200), FillRule::Winding, t);
            }
        }
        if rng.uniform() < 0.5 {
            let pw = rng.range(0.3, 0.6) as f32 * w;
            let (px, py) = (
                rng.range(0.0, (w - pw) as f64) as f32,
                rng.range(0.2, 0.6) as f32 * h,
            );
            self.poster(pm, rng, hue + 150.0, px, py, pw, pw * 1.3, t);
        }
    }

    /// `posters`: two or three framed posters.
    fn paint_posters(&self, pm: &mut Pixmap, rng: &mut Rng, hue: f64, at: &Placement) {
        let (w, h, t) = (at.w, at.h, at.t);
        for _ in 0..rng.range(2.0, 4.0) as usize {
            let pw = rng.range(0.25, 0.7) as f32 * w;
            let ph = pw * rng.range(0.7, 1.5) as f32;
            let px = rng.range(0.0, w as f64) as f32 - pw / 3.0;
            let py = rng.range(0.05 * h as f64, (h - ph).max(1.0) as f64) as f32;
            let dh = rng.range(0.0, 360.0);
            self.poster(pm, rng, hue + dh, px, py, pw, ph, t);
        }
    }

    /// A framed poster with a picture of blobs and lines of "text".
    #[allow(clippy::too_many_arguments)]
    fn poster(
        &self,
        pm: &mut Pixmap,
        rng: &mut Rng,
        hue: f64,
        x: f32,
        y: f32,
        w: f32,
        h: f32,
        t: Transform,
    ) {
        let frame = colour(rng, hue, 30.0);
        let paper = colour(rng, hue + 180.0, 30.0);
        if let Some(r) = Rect::from_xywh(x, y, w, h) {
            fill_rect(pm, r, &rgb(frame, 255), t);
        }
        if let Some(r) = Rect::from_xywh(x + 3.0, y + 3.0, w - 6.0, h - 6.0) {
            fill_rect(pm, r, &rgb(paper, 255), t);
        }
        for _ in 0..rng.range(2.0, 5.0) as usize {
            let mut pb = PathBuilder::new();
            let r = rng.range(0.06, 0.2) as f32 * w;
            pb.push_circle(
                x + rng.range(0.2, 0.8) as f32 * w,
                y + rng.range(0.15, 0.55) as f32 * h,
                r.max(1.0),
            );
            if let Some(p) = pb.finish() {
                fill_path(
                    pm,
                    &p,
                    &rgb(colour(rng, hue + 90.0, 150.0), 255),
                    FillRule::Winding,
                    t,
                );
            }
        }
        let ink = colour(rng, hue, 10.0);
        let lines = rng.range(2.0, 5.0) as usize;
        for i in 0..lines {
            let ly = y + h * (0.65 + 0.3 * i as f32 / lines as f32);
            let mut lx = x + 0.1 * w;
            while lx < x + 0.85 * w {
                let word = rng.range(0.05, 0.18) as f32 * w;
                if let Some(r) = Rect::from_xywh(
                    lx,
                    ly,
                    word.min(x + 0.9 * w - lx).max(1.0),
                    (0.035 * h).max(1.5),
                ) {
                    fill_rect(pm, r, &rgb(ink, 255), t);
                }
                lx += word + 0.04 * w;
            }
        }
    }
}

/// Where a chunk's shapes land: `w` texels per chunk, the pixmap's height
/// `h`, the shift `t` that places chunk `kk` beside the painted one.
struct Placement {
    w: f32,
    h: f32,
    t: Transform,
    kk: i64,
}

/// A rectangle at least one texel on a side.
fn texel_rect(x: f32, y: f32, rw: f32, rh: f32) -> Option<Rect> {
    Rect::from_xywh(x, y, rw.max(1.0), rh.max(1.0))
}

/// A disc of radius at least one texel.
fn push_disc(pb: &mut PathBuilder, x: f32, y: f32, r: f32) {
    pb.push_circle(x, y, r.max(1.0))
}

/// A wobbly closed curve: a circle with random harmonics.
fn blob(rng: &mut Rng, cx: f32, cy: f32, r: f32) -> Option<Path> {
    let mut pb = PathBuilder::new();
    let n = 12;
    let amp: Vec<f64> = (0..3).map(|_| rng.range(0.0, 0.3)).collect();
    let ph: Vec<f64> = (0..3)
        .map(|_| rng.range(0.0, std::f64::consts::TAU))
        .collect();
    for i in 0..=n {
        let a = i as f64 / n as f64 * std::f64::consts::TAU;
        let rr = r as f64
            * (1.0
                + amp[0] * (2.0 * a + ph[0]).sin()
                + amp[1] * (3.0 * a + ph[1]).sin()
                + amp[2] * (5.0 * a + ph[2]).sin());
        let (px, py) = (cx + (rr * a.cos()) as f32, cy + (rr * a.sin()) as f32);
        if i == 0 {
            pb.move_to(px, py);
        } else {
            pb.line_to(px, py);
        }
    }
    pb.close();
    pb.finish()
}

/// `signs`: discs, triangles, boxes and arrows, each with an inner disc.
fn paint_signs(pm: &mut Pixmap, rng: &mut Rng, hue: f64, at: &Placement) {
    let (w, h, t) = (at.w, at.h, at.t);
    for _ in 0..rng.range(3.0, 7.0) as usize {
        let r = rng.range(0.05, 0.18) as f32 * w;
        let (cx, cy) = (
            rng.range(0.0, w as f64) as f32,
            rng.range(0.1, 0.9) as f32 * h,
        );
        let c = {
            let dh = rng.range(0.0, 360.0);
            colour(rng, hue + dh, 40.0)
        };
        let mut pb = PathBuilder::new();
        match (rng.uniform() * 4.0) as u32 {
            0 => push_disc(&mut pb, cx, cy, r),
            1 => {
                pb.move_to(cx, cy - r);
                pb.line_to(cx + r, cy + r * 0.8);
                pb.line_to(cx - r, cy + r * 0.8);
                pb.close();
            }
            2 => {
                if let Some(rc) = texel_rect(cx - r, cy - r * 0.6, 2.0 * r, 1.2 * r) {
                    pb.push_rect(rc);
                }
            }
            _ => {
                pb.move_to(cx - r, cy - r * 0.3);
                pb.line_to(cx, cy - r * 0.3);
                pb.line_to(cx, cy - r);
                pb.line_to(cx + r, cy);
                pb.line_to(cx, cy + r);
                pb.line_to(cx, cy + r * 0.3);
                pb.line_to(cx - r, cy + r * 0.3);
                pb.close();
            }
        }
        if let Some(p) = pb.finish() {
            fill_path(pm, &p, &rgb(c, 255), FillRule::Winding, t);
            let inner = colour(rng, hue + 180.0, 60.0);
            let mut pb2 = PathBuilder::new();
            push_disc(&mut pb2, cx, cy, r * rng.range(0.2, 0.45) as f32);
            if let Some(p2) = pb2.finish() {
                fill_path(pm, &p2, &rgb(inner, 255), FillRule::Winding, t);
            }
        }
    }
}

/// `graffiti`: overlapping blobs and a few jagged strokes.
fn paint_graffiti(pm: &mut Pixmap, rng: &mut Rng, hue: f64, at: &Placement) {
    let (w, h, t) = (at.w, at.h, at.t);
    for _ in 0..rng.range(5.0, 10.0) as usize {
        let (cx, cy) = (
            rng.range(0.0, w as f64) as f32,
            rng.range(0.0, h as f64) as f32,
        );
        let c = {
            let dh = rng.range(-90.0, 90.0);
            colour(rng, hue + dh, 30.0)
        };
        if let Some(p) = {
            let radius = rng.range(5.0, 40.0) as f32;
            blob(rng, cx, cy, radius)
        } {
            fill_path(pm, &p, &rgb(c, 230), FillRule::Winding, t);
        }
    }
    for _ in 0..rng.range(1.0, 3.0) as usize {
        let mut pb = PathBuilder::new();
        let (mut x, mut y) = (
            rng.range(0.0, w as f64) as f32,
            rng.range(0.0, h as f64) as f32,
        );
        pb.move_to(x, y);
        for _ in 0..5 {
            x += rng.range(-40.0, 40.0) as f32;
            y += rng.range(-40.0, 40.0) as f32;
            pb.line_to(x, y);
        }
        if let Some(p) = pb.finish() {
            let stroke = Stroke {
                width: rng.range(2.0, 7.0) as f32,
                ..Stroke::default()
            };
            stroke_path(
                pm,
                &p,
                &rgb(colour(rng, hue + 180.0, 60.0), 255),
                &stroke,
                t,
            );
        }
    }
}

/// `tiles`: square tiles on the wall's grid, some with a disc.
fn paint_tiles(pm: &mut Pixmap, rng: &mut Rng, hue: f64, grid: &[f64; 4], at: &Placement) {
    let (w, h, t) = (at.w, at.h, at.t);
    let kk = at.kk;
    let s = grid[2] as f32 * w;
    let chunk_left = kk as f32 * w;
    let first = (chunk_left / s).ceil() as i64;
    let mut j = first;
    while (j as f32) * s - chunk_left < w {
        let tx = j as f32 * s - chunk_left;
        j += 1;
        for cy in 0..(h / s) as i32 + 1 {
            let c = colour(rng, hue, 60.0);
            if let Some(rc) = texel_rect(tx + 1.0, cy as f32 * s + 1.0, s - 2.0, s - 2.0) {
                fill_rect(pm, rc, &rgb(c, 255), t);
            }
            if rng.uniform() < 0.35 {
                let mut pb = PathBuilder::new();
                push_disc(
                    &mut pb,
                    tx + s / 2.0,
                    cy as f32 * s + s / 2.0,
                    s * rng.range(0.15, 0.4) as f32,
                );
                if let Some(p) = pb.finish() {
                    fill_path(
                        pm,
                        &p,
                        &rgb(colour(rng, hue + 180.0, 90.0), 255),
                        FillRule::Winding,
                        t,
                    );
                }
            }
        }
    }
}

/// `wood`: planks on the wall's grid, with knots.
fn paint_wood(pm: &mut Pixmap, rng: &mut Rng, hue: f64, grid: &[f64; 4], at: &Placement) {
    let (w, h, t) = (at.w, at.h, at.t);
    let kk = at.kk;
    let plank = grid[3] as f32 * w;
    let chunk_left = kk as f32 * w;
    let mut x = (chunk_left / plank).ceil() * plank - chunk_left;
    while x < w {
        let c = colour(rng, hue, 15.0);
        if let Some(rc) = texel_rect(x + 1.0, 0.0, plank - 2.0, h) {
            fill_rect(pm, rc, &rgb(c, 255), t);
        }
        for _ in 0..rng.range(1.0, 4.0) as usize {
            let (kx, ky) = (
                x + rng.range(0.2, 0.8) as f32 * plank,
                rng.range(0.0, h as f64) as f32,
            );
            if let Some(p) = {
                let radius = rng.range(3.0, 9.0) as f32;
                blob(rng, kx, ky, radius)
            } {
                fill_path(
                    pm,
                    &p,
                    &rgb(colour(rng, hue + 20.0, 20.0), 255),
                    FillRule::Winding,
                    t,
                );
            }
        }
        x += plank;
    }
}

/// `marble`: soft blobs and one vein from top to bottom.
fn paint_marble(pm: &mut Pixmap, rng: &mut Rng, hue: f64, at: &Placement) {
    let (w, h, t) = (at.w, at.h, at.t);
    for _ in 0..rng.range(8.0, 14.0) as usize {
        let (cx, cy) = (
            rng.range(0.0, w as f64) as f32,
            rng.range(0.0, h as f64) as f32,
        );
        if let Some(p) = {
            let radius = rng.range(4.0, 22.0) as f32;
            blob(rng, cx, cy, radius)
        } {
            fill_path(
                pm,
                &p,
                &rgb(colour(rng, hue, 50.0), 255),
                FillRule::Winding,
                t,
            );
        }
    }
    let mut pb = PathBuilder::new();
    let (mut x, mut y) = (rng.range(0.0, w as f64) as f32, 0.0f32);
    pb.move_to(x, y);
    while y < h {
        x += rng.range(-25.0, 25.0) as f32;
        y += rng.range(10.0, 40.0) as f32;
        pb.line_to(x, y);
    }
    if let Some(p) = pb.finish() {
        let stroke = Stroke {
            width: 2.5,
            ..Stroke::default()
        };
        stroke_path(
            pm,
            &p,
            &rgb(colour(rng, hue + 180.0, 40.0), 255),
            &stroke,
            t,
        );
    }
}
