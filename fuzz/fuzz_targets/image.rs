//! The image readers on arbitrary bytes: every format pbrs reads (PNG, TGA,
//! EXR, PFM, HDR), the first byte choosing which. Nothing may panic or
//! allocate beyond `MAX_IMAGE_PIXELS`; whatever decodes must be a
//! consistent image.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pbrs::loader::image::decode_image;
use std::path::Path;

const NAMES: [&str; 5] = ["f.png", "f.tga", "f.exr", "f.pfm", "f.hdr"];

fuzz_target!(|data: &[u8]| {
    let Some((&which, bytes)) = data.split_first() else {
        return;
    };
    let name = NAMES[which as usize % NAMES.len()];
    if let Ok(img) = decode_image(bytes, Path::new(name)) {
        assert_eq!(
            img.pixels().len() as u64,
            img.width() as u64 * img.height() as u64
        );
    }
});
