//! The scene's datasheet drives (`"drives"`) and thermal model (`"thermal"`), as written:
//! catalogue values in the units a datasheet prints them in (each key names its unit), or the
//! name of an entry of the shipped catalogue (`sim/catalogue/drives.json`). Validated and
//! converted to SI once, in `scene/drive.rs`.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// One datasheet drive: a motor (a catalogue name or its values) and optionally a gearhead, on
/// one or more joints. It replaces the `motor` values (torque constant, resistance, inductance,
/// rotor inertia, gear ratio, gear damping) of its joints; `motor`'s voltage and current limits
/// still apply.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DatasheetDriveSpec {
    /// The URDF joints that carry this drive (at least one; a joint in one drive only).
    pub joints: Vec<String>,
    /// A motor of the shipped catalogue by name (an unknown name is refused with the list); or give
    /// `motor_data`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motor: Option<String>,
    /// The motor's datasheet values; or give `motor` (a catalogue name).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motor_data: Option<MotorDatasheet>,
    /// A gearhead of the shipped catalogue by name (default: none, a direct drive, ratio 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gearhead: Option<String>,
    /// The gearhead's datasheet values, instead of a catalogue name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gearhead_data: Option<GearheadDatasheet>,
}

/// A DC motor's datasheet values, in the datasheet's units (maxon's line numbers in brackets).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MotorDatasheet {
    /// Nominal voltage, V [line 1] (shown by `sim check`; the supply limit is `motor.voltage_limit`).
    pub nominal_voltage_v: f64,
    /// No-load speed, rpm [line 2] (with the no-load current: the gear damping d_m = K_t I_0 / ω_0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub no_load_speed_rpm: Option<f64>,
    /// No-load current, mA [line 3].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub no_load_current_ma: Option<f64>,
    /// Nominal (max. continuous) current, A [line 6] (shown by `sim check`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nominal_current_a: Option<f64>,
    /// Terminal resistance, ohm [line 10], at `resistance_reference_temperature_c`.
    pub terminal_resistance_ohm: f64,
    /// Terminal inductance, mH [line 11].
    pub terminal_inductance_mh: f64,
    /// Torque constant, mNm/A [line 12].
    pub torque_constant_mnm_per_a: f64,
    /// Speed constant, rpm/V [line 13]: checked against the torque constant (k_n k_M = 30000/π
    /// within 2 %); the back-EMF constant is taken equal to the torque constant.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_constant_rpm_per_v: Option<f64>,
    /// Rotor inertia, g cm^2 [line 16].
    pub rotor_inertia_gcm2: f64,
    /// Thermal resistance housing–ambient R_th2, K/W [line 17].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermal_resistance_housing_ambient_k_per_w: Option<f64>,
    /// Thermal resistance winding–housing R_th1, K/W [line 18].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermal_resistance_winding_housing_k_per_w: Option<f64>,
    /// Thermal time constant of the winding τ_w, s [line 19].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermal_time_constant_winding_s: Option<f64>,
    /// Thermal time constant of the motor τ_s, s [line 20].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermal_time_constant_motor_s: Option<f64>,
    /// Max. winding temperature, °C [line 22] (monitored in the `limits` record).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_winding_temperature_c: Option<f64>,
    /// The temperature at which the terminal resistance is given, °C (default 25: maxon's sheets).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resistance_reference_temperature_c: Option<f64>,
    /// The winding's resistance temperature coefficient at 20 °C, 1/K (default 0.00393: copper,
    /// IEC 60028).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resistance_temperature_coefficient_per_k: Option<f64>,
}

/// A gearhead's datasheet values, in the datasheet's units.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GearheadDatasheet {
    /// Reduction (motor turns per output turn), e.g. 12 for 12:1.
    pub reduction: f64,
    /// Max. efficiency, % (shown by `sim check`; the gear friction model is not part of this drive).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_efficiency_percent: Option<f64>,
    /// Mass inertia, g cm^2, at the input (motor) shaft (default 0): added to the rotor's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia_gcm2: Option<f64>,
    /// Max. continuous torque at the output, N m (shown by `sim check`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_continuous_torque_nm: Option<f64>,
    /// Max. intermittent torque at the output, N m: monitored (`gear-torque` in the `limits`
    /// record) against the torque the drive delivers to its link.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_intermittent_torque_nm: Option<f64>,
}

/// `"thermal"`: the motors' two-node thermal model (winding and housing) on; every motor then
/// needs the four thermal values of its datasheet (a datasheet drive).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ThermalSpec {
    /// The ambient temperature T_a, °C (default 25).
    #[serde(default = "default_ambient")]
    pub ambient_temperature_c: f64,
    /// Winding and housing temperature at t = 0, °C (default: the ambient).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_temperature_c: Option<f64>,
}

fn default_ambient() -> f64 {
    25.0
}
