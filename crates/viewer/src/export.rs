//! What both platforms say when a PNG export is done (the desktop writes a file, the page
//! downloads one).

use fourfold::render::Picture;

use crate::notice::Notice;

/// The notice for `picture`, exported as `what` ("saved fourfold.png"): its size and time,
/// and a warning where the GPU driver cut pixels short.
pub fn exported(picture: &Picture, what: &str) -> Notice {
    let (w, h) = (picture.width, picture.height);
    let cut = picture.cut_pixels.len();
    let made = format!(
        "{what} ({w}x{h}, frame {:.0} ms on {})",
        picture.times.frame_ms, picture.adapter
    );
    if cut > 0 {
        Notice::error(format!(
            "{made}; the GPU cut {cut} pixels short: lower the rays or steps"
        ))
    } else {
        Notice::done(made)
    }
}
