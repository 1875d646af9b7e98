//! Reading ROS map_server maps (crate/src/formats/rosmap): YAML fields, PGM P5/P2
//! at 8 and 16 bits, PNG grey/RGB/RGBA, map_server's classification in
//! trinary, scale and raw modes, and every bad input naming file and field.

use image::ImageEncoder;
use slamlab::formats::rosmap::{self, MapYaml, Mode, MAX_CELLS};

const YAML: &str = "image: m.pgm\nresolution: 0.05\norigin: [-1.5, 2.0, 0.25]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";

fn yaml_with(extra: &str) -> String {
    format!("{YAML}{extra}")
}

/// A 3 x 2 binary PGM: top row 0 254 205, bottom row 100 255 10.
fn pgm8() -> Vec<u8> {
    let mut b = b"P5\n# made by hand\n3 2\n255\n".to_vec();
    b.extend([0u8, 254, 205, 100, 255, 10]);
    b
}

#[test]
fn yaml_fields_are_read_with_defaults() {
    let y = MapYaml::parse("a.yaml", YAML).unwrap();
    assert_eq!(y.image, "m.pgm");
    assert_eq!(y.resolution, 0.05);
    assert_eq!(y.origin, [-1.5, 2.0, 0.25]);
    assert!(!y.negate);
    assert_eq!(y.mode, Mode::Trinary);
    let y = MapYaml::parse(
        "a.yaml",
        "image: x.png\nresolution: 0.1\norigin: [0, 0, 0]\nmode: scale\nnegate: 1\n",
    )
    .unwrap();
    assert_eq!((y.occupied_thresh, y.free_thresh), (0.65, 0.196));
    assert!(y.negate);
    assert_eq!(y.mode, Mode::Scale);
}

#[test]
fn bad_yaml_names_the_file_and_the_field() {
    let cases: &[(&str, &str)] = &[
        ("resolution: 0.05\norigin: [0, 0, 0]\n", "image"),
        ("image: m.pgm\norigin: [0, 0, 0]\n", "resolution"),
        (
            "image: m.pgm\nresolution: -0.05\norigin: [0, 0, 0]\n",
            "resolution",
        ),
        (
            "image: m.pgm\nresolution: 0\norigin: [0, 0, 0]\n",
            "resolution",
        ),
        (
            "image: m.pgm\nresolution: .nan\norigin: [0, 0, 0]\n",
            "resolution",
        ),
        (
            "image: m.pgm\nresolution: .inf\norigin: [0, 0, 0]\n",
            "resolution",
        ),
        (
            "image: m.pgm\nresolution: fine\norigin: [0, 0, 0]\n",
            "resolution",
        ),
        ("image: m.pgm\nresolution: 0.05\n", "origin"),
        ("image: m.pgm\nresolution: 0.05\norigin: [0, 0]\n", "origin"),
        (
            "image: m.pgm\nresolution: 0.05\norigin: [0, .nan, 0]\n",
            "origin",
        ),
        (
            "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 2\n",
            "negate",
        ),
        (
            "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nmode: fancy\n",
            "mode",
        ),
        (
            "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\noccupied_thresh: 1.5\n",
            "occupied_thresh",
        ),
        (
            "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nfree_thresh: 0.9\n",
            "free_thresh",
        ),
        ("[1, 2, 3]\n", "yaml"),
        ("image: [\n", "yaml"),
    ];
    for (text, field) in cases {
        let e = MapYaml::parse("maps/b.yaml", text).unwrap_err();
        assert_eq!(e.file, "maps/b.yaml");
        assert_eq!(&e.field, field, "{text:?}: {e}");
        assert!(
            e.to_string()
                .starts_with(&format!("maps/b.yaml: {field}: ")),
            "{e}"
        );
    }
}

#[test]
fn binary_pgm_is_classified_as_map_server_does() {
    let m = rosmap::load("a.yaml", YAML, "m.pgm", &pgm8()).unwrap();
    assert_eq!((m.width, m.height), (3, 2));
    // Row 0 of the map is the image's bottom row: 100 255 10.
    // 100: p = 155/255 = 0.608, between the thresholds: unknown.
    // 255: p = 0, free. 10: p = 0.961, occupied.
    // Top row: 0 occupied, 254 free (p = 0.004), 205 unknown (p = 0.196 is not < 0.196).
    assert_eq!(m.data, vec![-1, 0, 100, 100, 0, -1]);
    assert_eq!(m.origin.x, -1.5);
    assert_eq!(m.origin.theta, 0.25);
}

#[test]
fn plain_and_sixteen_bit_pgm_read_like_the_binary_one() {
    let plain = b"P2\n# plain\n3 2\n# maxval next\n255\n0 254 205\n100 255 10\n";
    let a = rosmap::load("a.yaml", YAML, "m.pgm", plain).unwrap();
    let mut wide = b"P5\n3 2\n65535\n".to_vec();
    for v in [0u16, 254, 205, 100, 255, 10] {
        wide.extend((v * 257).to_be_bytes());
    }
    let b = rosmap::load("a.yaml", YAML, "m.pgm", &wide).unwrap();
    let c = rosmap::load("a.yaml", YAML, "m.pgm", &pgm8()).unwrap();
    assert_eq!(a.data, c.data);
    assert_eq!(b.data, c.data);
    // maxval 15: 15 is white (free), 0 black (occupied), 12 -> 204 (unknown).
    let small = b"P2 3 1 15 15 0 12";
    let d = rosmap::load("a.yaml", YAML, "m.pgm", small).unwrap();
    assert_eq!(d.data, vec![0, 100, -1]);
}

fn png(pixels: &[u8], w: u32, h: u32, colour: image::ExtendedColorType) -> Vec<u8> {
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(pixels, w, h, colour)
        .unwrap();
    out
}

#[test]
fn png_grey_rgb_and_rgba_follow_map_server() {
    let grey = png(
        &[0, 254, 205, 100, 255, 10],
        3,
        2,
        image::ExtendedColorType::L8,
    );
    let g = rosmap::load("a.yaml", YAML, "m.png", &grey).unwrap();
    assert_eq!(g.data, vec![-1, 0, 100, 100, 0, -1]);
    // RGB: the mean of the channels. (0, 0, 255) -> 85: p = 0.667 > 0.65, occupied;
    // (255, 255, 0) -> 170: p = 0.333, unknown; (255, 255, 255) free.
    let rgb = png(
        &[0, 0, 255, 255, 255, 0, 255, 255, 255],
        3,
        1,
        image::ExtendedColorType::Rgb8,
    );
    let c = rosmap::load("a.yaml", YAML, "m.png", &rgb).unwrap();
    assert_eq!(c.data, vec![100, -1, 0]);
    // RGBA in trinary mode: alpha is averaged in. White with alpha 0 -> 191.25:
    // p = 0.25, unknown; black opaque -> 63.75: p = 0.75, occupied.
    let rgba = png(
        &[255, 255, 255, 0, 0, 0, 0, 255],
        2,
        1,
        image::ExtendedColorType::Rgba8,
    );
    let t = rosmap::load("a.yaml", YAML, "m.png", &rgba).unwrap();
    assert_eq!(t.data, vec![-1, 100]);
    // In scale mode alpha is left out of the mean, and a transparent pixel
    // between the thresholds is unknown: grey 128 transparent -> -1,
    // grey 128 opaque -> 1 + 98 (0.498 - 0.196) / (0.65 - 0.196) = 66.
    let rgba = png(
        &[128, 128, 128, 0, 128, 128, 128, 255],
        2,
        1,
        image::ExtendedColorType::Rgba8,
    );
    let s = rosmap::load("a.yaml", &yaml_with("mode: scale\n"), "m.png", &rgba).unwrap();
    assert_eq!(s.data, vec![-1, 66]);
}

#[test]
fn negate_scale_and_raw_modes() {
    // negate: black is free, white occupied.
    let n = rosmap::load(
        "a.yaml",
        &yaml_with("negate: 1\n").replace("negate: 0\n", ""),
        "m.pgm",
        &pgm8(),
    )
    .unwrap();
    // 205 -> 50: p = 0.804, occupied.
    assert_eq!(n.data, vec![-1, 100, 0, 0, 100, 100]);
    // raw: the value is the cell; above 100 unknown.
    let raw = rosmap::load("a.yaml", &yaml_with("mode: raw\n"), "m.pgm", &pgm8()).unwrap();
    assert_eq!(raw.data, vec![100, -1, 10, 0, -1, -1]);
    // scale: 100 -> p = 0.608 -> 1 + 98 * 0.9075 = 89.9 -> 89; 205 -> p = 0.196: 1 + 0 = 1.
    let sc = rosmap::load("a.yaml", &yaml_with("mode: scale\n"), "m.pgm", &pgm8()).unwrap();
    assert_eq!(sc.data, vec![89, 0, 100, 100, 0, 1]);
    assert_eq!(
        rosmap::state_of_value(89),
        slamlab::slam::grid::CellState::Unknown
    );
}

#[test]
fn bad_images_are_refused_naming_the_file_and_field() {
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (b"GIF89a....".to_vec(), "not a PGM"),
        (b"P5\n3 2\n255\n\x00\x01".to_vec(), "cut short"),
        (b"P5\n3\n".to_vec(), "height"),
        (b"P5\n0 2\n255\n".to_vec(), "empty"),
        (b"P5\n3 2\n70000\n".to_vec(), "maxval"),
        (b"P2\n2 1\n255\n7\n".to_vec(), "ends after 1 of 2"),
        (b"P2\n2 1\n255\n7 x\n".to_vec(), "'x'"),
        (
            vec![0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a, 1, 2, 3],
            "PNG",
        ),
    ];
    for (bytes, what) in cases {
        let e = rosmap::load("dir/c.yaml", YAML, "m.pgm", &bytes).unwrap_err();
        assert_eq!(
            (e.file.as_str(), e.field.as_str()),
            ("dir/c.yaml", "image"),
            "{e}"
        );
        assert!(e.message.contains(what), "{what}: {e}");
        assert!(e.message.starts_with("m.pgm: "), "{e}");
    }
}

#[test]
fn images_over_the_size_limit_are_refused_before_decoding() {
    // 5000 x 5000 = 25 M cells: refused from the header alone.
    let e = rosmap::load("big.yaml", YAML, "m.pgm", b"P5\n5000 5000\n255\n").unwrap_err();
    assert_eq!(e.field, "image");
    assert!(e.message.contains("16777216"), "{e}");
    // 4096 x 4096 is allowed (the limit itself); check the arithmetic only.
    assert_eq!(MAX_CELLS, 4096 * 4096);
    // A PNG header claiming 5000 x 5000 is refused the same way.
    let mut header = png(&[255; 4], 2, 2, image::ExtendedColorType::L8);
    header[16..20].copy_from_slice(&5000u32.to_be_bytes());
    header[20..24].copy_from_slice(&5000u32.to_be_bytes());
    let crc = crc32(&header[12..29]);
    header[29..33].copy_from_slice(&crc.to_be_bytes());
    let e = rosmap::load("big.yaml", YAML, "m.png", &header).unwrap_err();
    assert!(e.message.contains("16777216"), "{e}");
}

#[test]
fn a_4000_square_map_loads() {
    let (w, h) = (4000usize, 4000usize);
    let mut b = format!("P5\n{w} {h}\n255\n").into_bytes();
    b.extend(std::iter::repeat_n(254u8, w * h));
    let m = rosmap::load("big.yaml", YAML, "m.pgm", &b).unwrap();
    assert_eq!((m.width, m.height), (w, h));
    assert!(m.data.iter().all(|&v| v == 0));
}

/// CRC-32 (ISO 3309, as PNG chunks use), bit by bit.
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = 0xffff_ffffu32;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xedb8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}
