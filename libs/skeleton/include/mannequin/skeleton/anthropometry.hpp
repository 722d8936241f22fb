#pragma once
/// \file anthropometry.hpp
/// \brief Builds a mannequin Model from stature, mass and sex with published tables.
///
/// Sources (see docs/mannequin-model.md for the full tables and the choices made):
/// - segment masses, centre-of-mass positions, radii of gyration and segment lengths:
///   de Leva P. (1996), Adjustments to Zatsiorsky–Seluyanov's segment inertia parameters,
///   J Biomech 29(9):1223–1230, Table 4 (male and female), lengths scaled by stature;
/// - ankle height, hand length, shoulder and hip widths (not in de Leva):
///   Drillis R., Contini R. (1966), Body segment parameters, Rep. 1166-03, New York University,
///   as tabulated in Winter D.A., Biomechanics and Motor Control of Human Movement, Fig. 4.1;
/// - joint ranges of motion: American Academy of Orthopaedic Surgeons (1965), Joint Motion:
///   Method of Measuring and Recording (averages for adults).
///
/// The zero configuration is the anatomical posture (standing, arms along the body, palms
/// forward). World and every joint frame at zero: x forward, y to the mannequin's left, z up.
/// Segment names: pelvis, abdomen, thorax, head, clavicle_{l,r}, upper_arm_{l,r}, forearm_{l,r},
/// hand_{l,r}, thigh_{l,r}, shank_{l,r}, foot_{l,r} (and toes_{l,r} when enabled).
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "mannequin/core/config.hpp"  // ConfigError
#include "mannequin/skeleton/model.hpp"

namespace mannequin::skeleton {

enum class Sex { kMale, kFemale };

/// What a mannequin config (configs/mannequins/*.yaml) specifies.
struct MannequinSpec {
  std::string name = "mannequin";
  Sex sex = Sex::kMale;
  double stature = 1.75;        ///< (m), vertex height standing
  double mass = 75.0;           ///< (kg)
  bool toes = false;            ///< add a toe segment and metatarsophalangeal joint per foot
  double density = 1050.0;      ///< body density (kg/m³) used to size the collision capsules
  /// Overrides of joint limits by coordinate name ("knee_l", "hip_l.y", ...), in degrees.
  std::map<std::string, std::pair<double, double>> limits_deg;
  /// Swing/twist limits of ball joints by joint name ("shoulder_l", ...), in degrees; what is not
  /// given comes from defaultBallLimit() (docs/constraints.md, "Joint limits, swing and twist").
  struct BallLimitDeg {
    std::optional<std::pair<double, double>> swing_axes;    ///< (a, b)
    std::optional<std::pair<double, double>> swing_center;  ///< (c_x, c_y)
    std::optional<std::pair<double, double>> twist;         ///< (lower, upper)
    std::optional<Vector3> twist_axis;                      ///< joint frame, normalised when read
  };
  std::map<std::string, BallLimitDeg> ball_limits_deg;
};

/// The swing/twist limits of ball joint `joint` derived from its box limits on the rotation-vector
/// components (model.lower_limit/upper_limit), which agree with swing and twist to first order:
/// t = unit vector from the joint centre to the CoM of the segment it carries (−z without one),
/// (e1, e2) = swingBasis(t); along e1, e2 the ellipse is inscribed in the box (centre = the box's
/// midpoints, semi-axes = its half-ranges), then, if it reaches past BallLimit::kMaxSwing, scaled
/// about s = 0 (centre and semi-axes by one factor: it still contains 0) to reach kMaxSwing; the twist range is the box's range of the component along t
/// (negated for t = −z), clipped to ±kMaxTwist.
BallLimit defaultBallLimit(const Model& model, int joint);

/// defaultBallLimit() overridden by `deg` (degrees). Not checked (see checkBallLimit()).
BallLimit ballLimitFromSpec(const Model& model, int joint, const MannequinSpec::BallLimitDeg& deg);

/// Builds the model (every ball joint gets swing/twist limits, see ball_limits_deg). \throws
/// std::invalid_argument for a stature outside [0.5, 2.5] m, a mass
/// outside [10, 300] kg, a non-finite value, a limit override naming an unknown coordinate, or
/// unusable swing/twist limits.
Model buildMannequin(const MannequinSpec& spec);

/// Parses a mannequin config from YAML text; `source` names it in errors.
/// \throws core::ConfigError "SOURCE:LINE: field 'key': message" (unknown key, value out of range, a limit
/// override naming no coordinate).
MannequinSpec parseMannequinSpec(const std::string& yaml_text, const std::string& source);

/// Reads and parses a config file. \throws core::ConfigError (unreadable file included, line 0).
MannequinSpec loadMannequinSpec(const std::string& path);

/// Configuration standing on the floor z = 0: the neutral posture with the pelvis raised so the
/// soles touch the floor.
VectorX standingConfiguration(const Model& model);

}  // namespace mannequin::skeleton
