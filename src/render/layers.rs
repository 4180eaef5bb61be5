//! Linear images in one EXR, as named layers: the first is what any viewer
//! shows; the rest carry what analysis needs beside it (a reference's
//! per-pixel variance, a shard's odd passes). Decoding refuses layers
//! larger than any image the program renders, before reading them.

use crate::fileio::SIGNATURE;
use crate::limits;
use crate::render::LinearImage;

/// The EXR of `layers` (all of one size), each under its name.
pub fn encode_layers(layers: &[(&str, &LinearImage)]) -> Result<Vec<u8>, String> {
    use exr::prelude::{Encoding, Image, ImageAttributes, IntegerBounds, Layer, LayerAttributes};
    use exr::prelude::{SpecificChannels, Vec2, WritableImage};
    let Some((_, first)) = layers.first() else { return Err("no layers".into()) };
    let (width, height) = (first.width as usize, first.height as usize);
    if let Some((name, wrong)) = layers.iter().find(|(_, image)| {
        (image.width, image.height) != (first.width, first.height) || image.pixels.len() != width * height
    }) {
        return Err(format!("a {}×{} layer “{name}” in a {width}×{height} image", wrong.width, wrong.height));
    }
    let layer = |(name, image): &(&str, &LinearImage)| {
        let pixels = image.pixels.clone();
        let mut attributes = LayerAttributes::named(*name);
        attributes.software_name = Some(SIGNATURE.into());
        let channels = SpecificChannels::rgb(move |Vec2(x, y): Vec2<usize>| {
            let [r, g, b] = pixels[y * width + x];
            (r, g, b)
        });
        Layer::new((width, height), attributes, Encoding::FAST_LOSSLESS, channels)
    };
    let attributes = ImageAttributes::new(IntegerBounds::from_dimensions((width, height)));
    let layers: Vec<_> = layers.iter().map(layer).collect();
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_layers(attributes, layers).write().to_buffered(&mut bytes).map_err(|e| e.to_string())?;
    Ok(bytes.into_inner())
}

/// Every layer of an EXR, in order, with its name, after its header says
/// they are no larger than the program renders; each finite and not
/// negative.
pub fn decode_layers(bytes: &[u8]) -> Result<Vec<(String, LinearImage)>, String> {
    use exr::prelude::{read, ReadChannels, ReadLayers};
    let meta =
        exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false).map_err(|e| e.to_string())?;
    for header in &meta.headers {
        let (w, h) = (header.layer_size.width() as u64, header.layer_size.height() as u64);
        if w > limits::IMAGE_SIDE.max as u64 || h > limits::IMAGE_SIDE.max as u64 || w * h > limits::IMAGE_PIXELS {
            return Err(format!("a {w}×{h} layer, larger than any image this program renders"));
        }
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| e.to_string())?;
    let layers = image.layer_data.iter().map(|layer| {
        let name = layer.attributes.layer_name.as_ref().map(|n| n.to_string()).unwrap_or_default();
        let (width, height) = (layer.size.width(), layer.size.height());
        let channel = |wanted: &str| {
            let found = layer.channel_data.list.iter().find(|c| c.name.to_string().eq_ignore_ascii_case(wanted));
            found.map(|c| c.sample_data.values_as_f32().collect::<Vec<f32>>())
        };
        let (Some(r), Some(g), Some(b)) = (channel("R"), channel("G"), channel("B")) else {
            return Err(format!("layer “{name}” has no R, G and B channels"));
        };
        let pixels: Vec<[f32; 3]> = (0..width * height).map(|i| [r[i], g[i], b[i]]).collect();
        if let Some(bad) = pixels.iter().flatten().find(|c| !c.is_finite() || **c < 0.0) {
            return Err(format!("layer “{name}” holds {bad}"));
        }
        Ok((name, LinearImage { width: width as u32, height: height as u32, pixels }))
    });
    let layers = layers.collect::<Result<Vec<_>, String>>()?;
    if layers.is_empty() {
        return Err("no layers".into());
    }
    Ok(layers)
}
