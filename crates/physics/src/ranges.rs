//! The physical ranges every number of a nominal model is checked against when it is read
//! ([`crate::NominalModel::from_json`]). They are generous: a 10 g micro-drone and a 100 kg
//! multirotor both fit, with room on either side, and gravity goes from the Moon's (1.62 m/s²) to
//! Jupiter's (24.8 m/s²). A number outside them is in other units, a typo or an overflow probe, and
//! would only reach an analysis as meaningless or non-finite numbers blamed on the recording.

use crate::error::readable;

/// A closed range `[min, max]` of one field of a model file, with its unit and what it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhysicalRange {
    /// The field as a model file spells it (`[i]` stands for each index of a list).
    pub field: &'static str,
    pub min: f64,
    pub max: f64,
    /// Empty, or the unit with a leading space.
    pub unit: &'static str,
    /// What the number is, for the error message.
    pub quantity: &'static str,
}

impl PhysicalRange {
    /// Fails with the message of a field error when `value` is not finite or lies outside the range.
    pub fn check(&self, value: f64) -> Result<f64, String> {
        if value.is_finite() && (self.min..=self.max).contains(&value) {
            return Ok(value);
        }
        Err(format!(
            "{} must be between {} and {}{}, found {}",
            self.quantity,
            readable(self.min),
            readable(self.max),
            self.unit,
            readable(value)
        ))
    }
}

/// The vehicle's mass: 1 g to 1 t.
pub const MASS_KG: PhysicalRange = PhysicalRange {
    field: "mass_kg",
    min: 1e-3,
    max: 1e3,
    unit: " kg",
    quantity: "the vehicle's mass",
};

/// Gravity: from a tenth of the Moon's to beyond Jupiter's.
pub const GRAVITY_M_S2: PhysicalRange = PhysicalRange {
    field: "gravity_m_s2",
    min: 0.1,
    max: 30.0,
    unit: " m/s²",
    quantity: "the acceleration of gravity",
};

/// Each principal moment of inertia: a 10 g micro-drone has about 2e-6 kg·m², a 100 kg
/// multirotor with 1.5 m arms about 50 kg·m².
pub const INERTIA_KG_M2: PhysicalRange = PhysicalRange {
    field: "inertia_kg_m2[i]",
    min: 1e-8,
    max: 1e4,
    unit: " kg·m²",
    quantity: "a principal moment of inertia",
};

/// The height of the ground plane: within the positions the data tools accept.
pub const GROUND_HEIGHT_M: PhysicalRange = PhysicalRange {
    field: "ground_height_m",
    min: -1e4,
    max: 1e4,
    unit: " m",
    quantity: "the ground's height",
};

/// The motor command at zero speed: within the `pwm` column's plausible range.
pub const PWM_OFFSET: PhysicalRange = PhysicalRange {
    field: "mixer.pwm_offset",
    min: 0.0,
    max: 1e5,
    unit: "",
    quantity: "the motor command at zero speed",
};

/// The span of motor commands from zero to full speed (1 for normalised commands, 1000 for PWM
/// microseconds).
pub const PWM_SCALE: PhysicalRange = PhysicalRange {
    field: "mixer.pwm_scale",
    min: 1e-3,
    max: 1e5,
    unit: "",
    quantity: "the motor command span from zero to full speed",
};

/// One rotor's thrust at full speed (the mixer's first row): a micro-drone's rotor makes about
/// 0.05 N, a 100 kg vehicle's about 1000 N.
pub const ROTOR_THRUST_N: PhysicalRange = PhysicalRange {
    field: "mixer.b0[0][j]",
    min: 1e-3,
    max: 1e5,
    unit: " N",
    quantity: "a rotor's thrust at full speed",
};

/// One rotor's torque at full speed (the mixer's torque rows: arm × thrust, or the rotor's drag
/// torque); either sign.
pub const ROTOR_TORQUE_N_M: PhysicalRange = PhysicalRange {
    field: "mixer.b0[i][j], i = 1..3",
    min: -1e5,
    max: 1e5,
    unit: " N·m",
    quantity: "a rotor's torque at full speed",
};

/// The rotors' total thrust at full speed over the vehicle's weight: a vehicle that cannot lift
/// itself cannot fly, and no multirotor comes near 100.
pub const THRUST_TO_WEIGHT: PhysicalRange = PhysicalRange {
    field: "mixer.b0[0] / (mass_kg · gravity_m_s2)",
    min: 1.0,
    max: 100.0,
    unit: "",
    quantity: "the rotors' total thrust at full speed over the weight",
};

/// The controller's rate: flight controllers run from tens of hertz to 32 kHz.
pub const CONTROLLER_RATE_HZ: PhysicalRange = PhysicalRange {
    field: "logger.controller_rate_hz",
    min: 1.0,
    max: 1e5,
    unit: " Hz",
    quantity: "the controller's rate",
};

/// Every range a model file is checked against (the logger's time offset and rate filter have
/// their own bounds: [`crate::MAX_COMMAND_OFFSET_S`], [`crate::MIN_RATE_LOW_PASS_HZ`] and
/// [`crate::MAX_RATE_LOW_PASS_HZ`]).
pub const MODEL_RANGES: [PhysicalRange; 10] = [
    MASS_KG,
    GRAVITY_M_S2,
    INERTIA_KG_M2,
    GROUND_HEIGHT_M,
    PWM_OFFSET,
    PWM_SCALE,
    ROTOR_THRUST_N,
    ROTOR_TORQUE_N_M,
    THRUST_TO_WEIGHT,
    CONTROLLER_RATE_HZ,
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_range_refuses_what_lies_outside_it_and_says_so_in_its_units() {
        assert_eq!(MASS_KG.check(1.8), Ok(1.8));
        assert_eq!(MASS_KG.check(1e-3), Ok(1e-3));
        let message = MASS_KG.check(1e300).unwrap_err();
        assert_eq!(
            message,
            "the vehicle's mass must be between 0.001 and 1000 kg, found 1e300"
        );
        assert!(MASS_KG.check(f64::NAN).is_err());
        assert!(MASS_KG.check(0.0).is_err());
        assert!(ROTOR_TORQUE_N_M.check(0.0).is_ok());
        assert!(ROTOR_TORQUE_N_M.check(-1.08).is_ok());
    }
}
