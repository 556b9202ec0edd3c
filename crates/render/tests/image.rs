//! Image encoding: tone mapping, PNG round trip, EXR header, format selection.

use dualsplit_render::{Image, RenderError, srgb_encode};

fn ramp() -> Image {
    let mut img = Image::new(7, 3);
    for (i, p) in img.pixels.iter_mut().enumerate() {
        *p = i as f32 / 10.0 - 0.3;
    }
    img.pixels[5] = f32::NAN;
    img.pixels[6] = f32::INFINITY;
    img
}

#[test]
fn tone_mapping_clamps_and_applies_srgb() {
    let img = ramp();
    let bytes = img.to_srgb8();
    for (i, (&v, &b)) in img.pixels.iter().zip(&bytes).enumerate() {
        let want = if v.is_nan() || v <= 0.0 {
            0
        } else if v >= 1.0 {
            255
        } else {
            (srgb_encode(v) * 255.0).round() as u8
        };
        assert_eq!(b, want, "pixel {i} = {v}");
    }
    assert!((srgb_encode(0.5) - 0.735_356_7).abs() < 1e-5);
}

#[test]
fn png_round_trips_the_tone_mapped_bytes() {
    let img = ramp();
    let mut buf = Vec::new();
    img.encode_png(&mut buf).unwrap();
    let dec = png::Decoder::new(std::io::Cursor::new(buf));
    let mut reader = dec.read_info().unwrap();
    let mut out = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut out).unwrap();
    assert_eq!((info.width, info.height), (7, 3));
    assert_eq!(info.color_type, png::ColorType::Grayscale);
    assert_eq!(&out[..info.buffer_size()], &img.to_srgb8()[..]);
}

#[test]
fn files_are_chosen_by_extension() {
    let dir = std::env::temp_dir().join(format!("dualsplit-render-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let img = ramp();
    img.write(&dir.join("a.PNG")).unwrap();
    let png = std::fs::read(dir.join("a.PNG")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    img.write(&dir.join("a.exr")).unwrap();
    let exr = std::fs::read(dir.join("a.exr")).unwrap();
    assert_eq!(&exr[..4], &[0x76, 0x2f, 0x31, 0x01], "OpenEXR magic number");
    assert!(matches!(
        img.write(&dir.join("a.jpg")),
        Err(RenderError::UnknownFormat { .. })
    ));
    assert!(matches!(
        img.write(&dir.join("no/such/dir/a.png")),
        Err(RenderError::Write { .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}
