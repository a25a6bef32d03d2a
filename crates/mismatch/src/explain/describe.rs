//! Plain words for effects: each effect's own sentence, from the registry.

use physics::{EffectId, Effects};

/// One sentence for effect `id` of `effects` (its neutral values when absent), in plain words,
/// for a vehicle under gravity `gravity_m_s2`.
pub fn describe(id: EffectId, effects: &Effects, gravity_m_s2: f64) -> String {
    effects
        .parameters(id)
        .unwrap_or_else(|| id.neutral())
        .describe(gravity_m_s2)
}
