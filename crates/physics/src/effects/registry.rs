//! What the registry's list (in the [module](super)) generates: each line names an effect's type
//! (a file of this folder, named as its id, implementing [`EffectKind`]); from the list come the
//! file's module, [`EffectId`], the set [`Effects`], [`EffectParameters`] and the per-id dispatch.
//! The list's order is the vocabulary's: the order of the JSON keys, of reports, and of every sum
//! and product the equations of motion compose.

use super::{EffectId, EffectParameters, ParameterValue};

macro_rules! vocabulary {
    ($($variant:ident $field:ident;)*) => {
        $(
            mod $field;
            pub use $field::$variant;
        )*

        /// One effect of the vocabulary (see the [module](super) for their parameters and physics).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
        #[serde(rename_all = "snake_case")]
        pub enum EffectId {
            $($variant,)*
        }

        impl EffectId {
            /// Every effect, in the vocabulary's order.
            pub const ALL: [EffectId; [$(stringify!($variant)),*].len()] = [$(Self::$variant),*];

            /// The id as files and reports spell it (`linear_drag`).
            pub const fn name(self) -> &'static str {
                match self {
                    $(Self::$variant => stringify!($field),)*
                }
            }

            /// The values that leave the nominal model unchanged.
            pub fn neutral(self) -> EffectParameters {
                match self {
                    $(Self::$variant => EffectParameters::$variant(<$variant as EffectKind>::NEUTRAL),)*
                }
            }

            /// The range a fit keeps number `index` of the effect in.
            pub fn fit_range(self, index: usize) -> (f64, f64) {
                match self {
                    $(Self::$variant => <$variant as EffectKind>::fit_range(index),)*
                }
            }

            /// The spacing of the profile grid of number `index` of the effect (none: not profiled).
            pub fn profile_step(self, index: usize) -> Option<f64> {
                match self {
                    $(Self::$variant => <$variant as EffectKind>::profile_step(index),)*
                }
            }

            /// A typical magnitude of number `index`, for finite-difference steps.
            pub fn typical(self, index: usize) -> f64 {
                match self {
                    $(Self::$variant => <$variant as EffectKind>::typical(index),)*
                }
            }

            /// The channels the effect acts on.
            pub fn acts_on(self) -> ChannelGroup {
                match self {
                    $(Self::$variant => <$variant as EffectKind>::ACTS_ON,)*
                }
            }

            /// Whether its numbers are factors (1 leaves the model unchanged).
            pub fn is_factor(self) -> bool {
                match self {
                    $(Self::$variant => <$variant as EffectKind>::FACTOR,)*
                }
            }

            /// Whether it describes the air a flight met rather than the vehicle.
            pub fn describes_the_air(self) -> bool {
                match self {
                    $(Self::$variant => <$variant as EffectKind>::DESCRIBES_THE_AIR,)*
                }
            }

            /// Effects one of which must be present for it to act.
            pub fn needs(self) -> Option<Needs> {
                match self {
                    $(Self::$variant => <$variant as EffectKind>::NEEDS,)*
                }
            }

            /// Start values of a nonlinear fit of all its numbers (none: start neutral).
            pub fn fit_starts(self) -> Vec<Vec<f64>> {
                match self {
                    $(Self::$variant => <$variant as EffectKind>::fit_starts(),)*
                }
            }

            /// The single-recording screen's terms for the effect, each with its perturbed effect
            /// set (that effect alone) and step; `None` when it is not screened.
            pub fn screening(self, sample_interval_s: f64) -> Option<(Vec<Term>, Vec<(Effects, f64)>)> {
                match self {
                    $(Self::$variant => <$variant as EffectKind>::screening(sample_interval_s).map(|s| {
                        let perturbed = s
                            .perturbations
                            .into_iter()
                            .map(|(value, step)| {
                                let mut effects = Effects::default();
                                effects.$field = Some(value);
                                (effects, step)
                            })
                            .collect();
                        (s.terms, perturbed)
                    }),)*
                }
            }
        }

        /// A set of effects; `None` means absent. Serialises as `{"<id>": {<parameters>}, ...}`.
        #[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
        #[serde(deny_unknown_fields)]
        pub struct Effects {
            $(
                #[serde(default, skip_serializing_if = "Option::is_none")]
                pub $field: Option<$variant>,
            )*
        }

        impl Effects {
            /// Whether effect `id` is present.
            pub fn contains(&self, id: EffectId) -> bool {
                match id {
                    $(EffectId::$variant => self.$field.is_some(),)*
                }
            }

            /// The parameters of effect `id`, when present.
            pub fn parameters(&self, id: EffectId) -> Option<EffectParameters> {
                match id {
                    $(EffectId::$variant => self.$field.map(EffectParameters::$variant),)*
                }
            }

            /// Removes effect `id` (nothing else: see [`Effects::without`]).
            pub fn remove(&mut self, id: EffectId) {
                match id {
                    $(EffectId::$variant => self.$field = None,)*
                }
            }

            /// Adds (or replaces) an effect.
            pub fn insert(&mut self, parameters: EffectParameters) {
                match parameters {
                    $(EffectParameters::$variant(p) => self.$field = Some(p),)*
                }
            }

            /// `f` folded over the effects present, in vocabulary order.
            pub(crate) fn fold<T>(&self, start: T, mut f: impl FnMut(T, &dyn Effect) -> T) -> T {
                let mut value = start;
                $(
                    if let Some(effect) = &self.$field {
                        value = f(value, effect);
                    }
                )*
                value
            }

            /// `f` on each effect present, in vocabulary order.
            pub fn for_each(&self, mut f: impl FnMut(&dyn Effect)) {
                self.fold((), |(), effect| f(effect));
            }
        }

        /// One effect's parameters: serialises as that effect's entry in [`Effects`]' JSON.
        #[derive(Clone, Copy, Debug, PartialEq, Serialize)]
        #[serde(untagged)]
        pub enum EffectParameters {
            $($variant($variant),)*
        }

        impl EffectParameters {
            /// The parameters as an effect.
            pub fn effect(&self) -> &dyn Effect {
                match self {
                    $(Self::$variant(p) => p,)*
                }
            }

            /// Effect `id` with these numbers (in the order of [`Effect::numbers`]).
            pub fn from_numbers(id: EffectId, numbers: &[f64]) -> Self {
                match id {
                    $(EffectId::$variant => Self::$variant(<$variant as EffectKind>::from_numbers(numbers)),)*
                }
            }
        }
    };
}

pub(super) use vocabulary;

impl EffectParameters {
    /// The effect these parameters belong to.
    pub fn id(&self) -> EffectId {
        self.effect().id()
    }

    /// Each parameter's name and value, in the order of the keys of its JSON.
    pub fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        self.effect().values()
    }

    /// Every number, in order.
    pub fn numbers(&self) -> Vec<f64> {
        self.effect().numbers()
    }

    /// One sentence in plain words, for a vehicle under gravity `gravity_m_s2`.
    pub fn describe(&self, gravity_m_s2: f64) -> String {
        self.effect().describe(gravity_m_s2)
    }
}
