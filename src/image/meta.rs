//! Reading any image pbrs reads (EXR, PFM, PNG, TGA, HDR) as linear RGB with
//! its format and text metadata, for the image tools (`pbrs img`, `pbrs
//! test`), and the metadata pbrs writes into its renders.

use super::io::{format_for_path, ImageFormat};
use super::Image;
use std::path::Path;

/// Keys of the metadata pbrs writes into rendered EXR and PNG files.
pub const KEY_VERSION: &str = "pbrsVersion";
pub const KEY_SCENE: &str = "pbrsScene";
pub const KEY_SPP: &str = "pbrsSpp";
pub const KEY_INTEGRATOR: &str = "pbrsIntegrator";
pub const KEY_SEED: &str = "pbrsSeed";
pub const KEY_RENDER_TIME: &str = "pbrsRenderTime";

/// The metadata of a render: pbrs's version, the scene file(s), samples per
/// pixel, integrator, seed and render time in seconds.
pub fn render_metadata(
    scene: &str,
    spp: u32,
    integrator: &str,
    seed: u64,
    render_seconds: f64,
) -> Vec<(String, String)> {
    [
        (KEY_VERSION, env!("CARGO_PKG_VERSION").to_string()),
        (KEY_SCENE, scene.to_string()),
        (KEY_SPP, spp.to_string()),
        (KEY_INTEGRATOR, integrator.to_string()),
        (KEY_SEED, seed.to_string()),
        (KEY_RENDER_TIME, format!("{render_seconds:.3}")),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect()
}

/// An image file as read by [`read_any`].
#[derive(Clone, Debug)]
pub struct ImageFile {
    /// Linear RGB (8-bit files decoded from sRGB).
    pub image: Image,
    pub format: ImageFormat,
    /// The file's own channels before conversion to RGB (e.g. "RGB", "RGBA").
    pub channels: String,
    /// Text metadata (EXR text attributes, PNG text chunks), in file order.
    pub metadata: Vec<(String, String)>,
}

impl ImageFile {
    pub fn get(&self, key: &str) -> Option<&str> {
        self.metadata
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

/// Reads an image of any format pbrs reads; errors name the file and say
/// what is wrong (missing, empty, truncated or corrupt, unknown format).
pub fn read_any(path: &Path) -> Result<ImageFile, String> {
    let format = format_for_path(path)?;
    let fail = |e: String| format!("{}: {e}", path.display());
    let bytes = std::fs::read(path).map_err(|e| fail(e.to_string()))?;
    let rgb = crate::loader::image::decode_image(&bytes, path).map_err(|e| {
        fail(format!(
            "cannot read it as {} (truncated or corrupt?): {e}",
            format.name()
        ))
    })?;
    let eight = rgb.depth() == crate::scene::SampleDepth::U8;
    let conv = |v: f32| {
        if eight {
            crate::scene::image::srgb_to_linear(v)
        } else {
            v
        }
    };
    let data = rgb
        .pixels()
        .iter()
        .flat_map(|p| [conv(p.x), conv(p.y), conv(p.z)])
        .collect();
    let image = Image {
        width: rgb.width(),
        height: rgb.height(),
        data,
    };
    let (channels, metadata) = match format {
        ImageFormat::Exr => exr_channels_and_text(&bytes).map_err(fail)?,
        ImageFormat::Png => png_channels_and_text(&bytes).map_err(fail)?,
        ImageFormat::Pfm => {
            let grey = bytes.starts_with(b"Pf");
            ((if grey { "Y" } else { "RGB" }).to_string(), Vec::new())
        }
        ImageFormat::Hdr => ("RGB (RGBE)".to_string(), Vec::new()),
        ImageFormat::Tga => ("RGB(A) 8-bit".to_string(), Vec::new()),
    };
    Ok(ImageFile {
        image,
        format,
        channels,
        metadata,
    })
}

type ChannelsAndText = (String, Vec<(String, String)>);

fn exr_channels_and_text(bytes: &[u8]) -> Result<ChannelsAndText, String> {
    use exr::prelude::AttributeValue;
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
        .map_err(|e| e.to_string())?;
    let Some(h) = meta.headers.first() else {
        return Err("an EXR without a header".into());
    };
    let channels: Vec<String> = h.channels.list.iter().map(|c| c.name.to_string()).collect();
    let mut text = Vec::new();
    let attrs = h
        .shared_attributes
        .other
        .iter()
        .chain(&h.own_attributes.other);
    for (k, v) in attrs {
        if let AttributeValue::Text(t) = v {
            text.push((k.to_string(), t.to_string()));
        }
    }
    text.sort();
    Ok((channels.join(","), text))
}

fn png_channels_and_text(bytes: &[u8]) -> Result<ChannelsAndText, String> {
    let dec = png::Decoder::new(std::io::Cursor::new(bytes));
    let reader = dec.read_info().map_err(|e| e.to_string())?;
    let info = reader.info();
    let channels = format!("{:?} {}-bit", info.color_type, info.bit_depth as u8);
    let mut text = Vec::new();
    for t in &info.uncompressed_latin1_text {
        text.push((t.keyword.clone(), t.text.clone()));
    }
    for t in &info.utf8_text {
        if let Ok(s) = t.get_text() {
            text.push((t.keyword.clone(), s));
        }
    }
    Ok((channels, text))
}
