//! winit's keys as the viewer's own [`Key`]s (the controls are tested without a window).

use super::controls::Key;
use winit::keyboard::{Key as WKey, NamedKey};

/// The viewer key `key` stands for, if any.
pub(super) fn map_key(key: &WKey) -> Option<Key> {
    Some(match key {
        WKey::Named(NamedKey::Escape) => Key::Escape,
        WKey::Named(NamedKey::ArrowLeft) => Key::Left,
        WKey::Named(NamedKey::ArrowRight) => Key::Right,
        WKey::Named(NamedKey::ArrowUp) => Key::Up,
        WKey::Named(NamedKey::ArrowDown) => Key::Down,
        WKey::Named(NamedKey::Space) => Key::Space,
        WKey::Character(c) => match c.as_str() {
            "w" | "W" => Key::W,
            "+" | "=" => Key::Plus,
            "-" | "_" => Key::Minus,
            " " => Key::Space,
            "1" => Key::Digit(1),
            "2" => Key::Digit(2),
            "3" => Key::Digit(3),
            "m" | "M" => Key::M,
            "p" | "P" => Key::P,
            "." => Key::Period,
            "r" | "R" => Key::R,
            "f" | "F" => Key::F,
            "s" | "S" => Key::S,
            "h" | "H" => Key::H,
            _ => return None,
        },
        _ => return None,
    })
}
