#pragma once
// Magic Formula tire property files (.tir, the TeimOrbit format of MSC Adams,
// MF-Tyre and Project Chrono) read into MagicFormulaCoefficients in SI units.
//
// Format: `[SECTION]` headers; `KEY = value` lines; values are numbers or
// strings in single or double quotes; `$` and `!` start a comment (outside
// quotes) that runs to the end of the line; table sections ([SHAPE],
// [BOTTOMING_CURVE], ...) hold a `{column names}` line and rows of numbers
// (read and unused). The [UNITS] section (LENGTH, FORCE, ANGLE, MASS, TIME,
// PRESSURE) gives the units of the dimensional keys, each converted to SI by
// its dimension (UNLOADED_RADIUS a length, VERTICAL_STIFFNESS force/length,
// VERTICAL_DAMPING force time/length, FNOMIN a force, NOMPRES a pressure,
// LONGVL a speed, ALPMIN an angle, ...). The Magic Formula coefficients and
// scaling factors are dimensionless (slips in rad, loads as dfz), as the
// standard writes them, whatever [UNITS] says.
//
// Errors (vdyn::Error) name the file, the line, the key and the value: an
// unknown section, an unknown key, a key outside a section, a value that is
// no number, an unknown unit, a FITTYP other than 6, 61, 62, a missing
// required key (UNLOADED_RADIUS, FNOMIN, VERTICAL_STIFFNESS and the Fx, Fy
// cores PCX1 PDX1 PKX1 PCY1 PDY1 PKY1 PKY2), a non-positive radius, load or
// stiffness. A model key the file leaves out takes its documented default
// (below: 0 for most coefficients, 1 for the scaling factors, PKY4 = 2 as
// PAC2002 fixes it, Q_RE0 = 1, QSY7 = 1, VXLOW = 1 m/s, LONGVL = 16.7 m/s) and
// is listed in TirFile::defaulted_keys.
#include <limits>
#include <string>
#include <vector>

namespace vdyn::mf {

/// The side of the vehicle a tire was measured for (TYRESIDE) or is mounted on.
enum class TireSide { Left, Right, Symmetric };

// The keys the model reads: X(NAME, dimension, default). NAME is the key's
// name in the file (and the member's name); NaN as default = required key.
// Dimensions: None (dimensionless or rad as the MF standard writes it),
// Length (m), Force (N), Angle (rad), Mass (kg), Pressure (Pa), Speed (m/s),
// Stiffness (N/m), Damping (N s/m).
#define VDYN_MF_KEYS(X)                                                                         \
  /* [MODEL] */                                                                                 \
  X(LONGVL, Speed, 16.7) /* reference speed V0 of the measurements, m/s */                      \
  X(VXLOW, Speed, 1.0)   /* below |Vx| = VXLOW My and the residual torque fade out, m/s */      \
  /* [DIMENSION] */                                                                             \
  X(UNLOADED_RADIUS, Length, kRequired) /* R0, m */                                             \
  X(WIDTH, Length, 0.0)                                                                         \
  /* [OPERATING_CONDITIONS] */                                                                  \
  X(INFLPRES, Pressure, 0.0) /* inflation pressure, Pa; 0: NOMPRES */                           \
  X(NOMPRES, Pressure, 0.0)  /* nominal pressure pi0, Pa; 0: no pressure dependence */          \
  /* [VERTICAL] */                                                                              \
  X(FNOMIN, Force, kRequired)             /* nominal load Fz0, N */                             \
  X(VERTICAL_STIFFNESS, Stiffness, kRequired) /* Cz, N/m */                                     \
  X(VERTICAL_DAMPING, Damping, 0.0)       /* N s/m */                                           \
  X(BREFF, None, 0.0) X(DREFF, None, 0.0) X(FREFF, None, 0.0)                                   \
  X(Q_RE0, None, 1.0) X(Q_V1, None, 0.0)                                                        \
  /* [SCALING_COEFFICIENTS] */                                                                  \
  X(LFZO, None, 1.0) X(LCX, None, 1.0) X(LMUX, None, 1.0) X(LEX, None, 1.0) X(LKX, None, 1.0)  \
  X(LHX, None, 1.0) X(LVX, None, 1.0) X(LCY, None, 1.0) X(LMUY, None, 1.0) X(LEY, None, 1.0)   \
  X(LKY, None, 1.0) X(LKYC, None, 1.0) X(LKZC, None, 1.0) X(LHY, None, 1.0) X(LVY, None, 1.0)  \
  X(LTR, None, 1.0) X(LRES, None, 1.0) X(LXAL, None, 1.0) X(LYKA, None, 1.0)                   \
  X(LVYKA, None, 1.0) X(LS, None, 1.0) X(LMX, None, 1.0) X(LVMX, None, 1.0) X(LMY, None, 1.0)  \
  X(LSGKP, None, 1.0) X(LSGAL, None, 1.0)                                                       \
  /* [LONGITUDINAL_COEFFICIENTS] */                                                             \
  X(PCX1, None, kRequired) X(PDX1, None, kRequired) X(PDX2, None, 0.0) X(PDX3, None, 0.0)      \
  X(PEX1, None, 0.0) X(PEX2, None, 0.0) X(PEX3, None, 0.0) X(PEX4, None, 0.0)                  \
  X(PKX1, None, kRequired) X(PKX2, None, 0.0) X(PKX3, None, 0.0)                               \
  X(PHX1, None, 0.0) X(PHX2, None, 0.0) X(PVX1, None, 0.0) X(PVX2, None, 0.0)                  \
  X(PPX1, None, 0.0) X(PPX2, None, 0.0) X(PPX3, None, 0.0) X(PPX4, None, 0.0)                  \
  X(RBX1, None, 0.0) X(RBX2, None, 0.0) X(RBX3, None, 0.0) X(RCX1, None, 0.0)                  \
  X(REX1, None, 0.0) X(REX2, None, 0.0) X(RHX1, None, 0.0)                                     \
  X(PTX1, None, 0.0) X(PTX2, None, 0.0) X(PTX3, None, 0.0)                                     \
  /* [OVERTURNING_COEFFICIENTS] */                                                              \
  X(QSX1, None, 0.0) X(QSX2, None, 0.0) X(QSX3, None, 0.0) X(QSX4, None, 0.0)                  \
  X(QSX5, None, 0.0) X(QSX6, None, 0.0) X(QSX7, None, 0.0) X(QSX8, None, 0.0)                  \
  X(QSX9, None, 0.0) X(QSX10, None, 0.0) X(QSX11, None, 0.0) X(QSX12, None, 0.0)               \
  X(QSX13, None, 0.0) X(QSX14, None, 0.0) X(PPMX1, None, 0.0)                                  \
  /* [LATERAL_COEFFICIENTS] */                                                                  \
  X(PCY1, None, kRequired) X(PDY1, None, kRequired) X(PDY2, None, 0.0) X(PDY3, None, 0.0)      \
  X(PEY1, None, 0.0) X(PEY2, None, 0.0) X(PEY3, None, 0.0) X(PEY4, None, 0.0)                  \
  X(PEY5, None, 0.0)                                                                            \
  X(PKY1, None, kRequired) X(PKY2, None, kRequired) X(PKY3, None, 0.0) X(PKY4, None, 2.0)      \
  X(PKY5, None, 0.0) X(PKY6, None, 0.0) X(PKY7, None, 0.0)                                     \
  X(PHY1, None, 0.0) X(PHY2, None, 0.0) X(PHY3, None, 0.0)                                     \
  X(PVY1, None, 0.0) X(PVY2, None, 0.0) X(PVY3, None, 0.0) X(PVY4, None, 0.0)                  \
  X(PPY1, None, 0.0) X(PPY2, None, 0.0) X(PPY3, None, 0.0) X(PPY4, None, 0.0)                  \
  X(PPY5, None, 0.0)                                                                            \
  X(RBY1, None, 0.0) X(RBY2, None, 0.0) X(RBY3, None, 0.0) X(RBY4, None, 0.0)                  \
  X(RCY1, None, 0.0) X(REY1, None, 0.0) X(REY2, None, 0.0) X(RHY1, None, 0.0)                  \
  X(RHY2, None, 0.0) X(RVY1, None, 0.0) X(RVY2, None, 0.0) X(RVY3, None, 0.0)                  \
  X(RVY4, None, 0.0) X(RVY5, None, 0.0) X(RVY6, None, 0.0)                                     \
  X(PTY1, None, 0.0) X(PTY2, None, 0.0)                                                        \
  /* [ROLLING_COEFFICIENTS] */                                                                  \
  X(QSY1, None, 0.0) X(QSY2, None, 0.0) X(QSY3, None, 0.0) X(QSY4, None, 0.0)                  \
  X(QSY5, None, 0.0) X(QSY6, None, 0.0) X(QSY7, None, 1.0) X(QSY8, None, 0.0)                  \
  /* [ALIGNING_COEFFICIENTS] */                                                                 \
  X(QBZ1, None, 0.0) X(QBZ2, None, 0.0) X(QBZ3, None, 0.0) X(QBZ4, None, 0.0)                  \
  X(QBZ5, None, 0.0) X(QBZ6, None, 0.0) X(QBZ9, None, 0.0) X(QBZ10, None, 0.0)                 \
  X(QCZ1, None, 0.0) X(QDZ1, None, 0.0) X(QDZ2, None, 0.0) X(QDZ3, None, 0.0)                  \
  X(QDZ4, None, 0.0) X(QDZ6, None, 0.0) X(QDZ7, None, 0.0) X(QDZ8, None, 0.0)                  \
  X(QDZ9, None, 0.0) X(QDZ10, None, 0.0) X(QDZ11, None, 0.0)                                   \
  X(QEZ1, None, 0.0) X(QEZ2, None, 0.0) X(QEZ3, None, 0.0) X(QEZ4, None, 0.0)                  \
  X(QEZ5, None, 0.0) X(QHZ1, None, 0.0) X(QHZ2, None, 0.0) X(QHZ3, None, 0.0)                  \
  X(QHZ4, None, 0.0) X(PPZ1, None, 0.0) X(PPZ2, None, 0.0)                                     \
  X(SSZ1, None, 0.0) X(SSZ2, None, 0.0) X(SSZ3, None, 0.0) X(SSZ4, None, 0.0)

/// Marks a key without a default (the reader's error names it when missing).
inline constexpr double kRequired = std::numeric_limits<double>::quiet_NaN();

/// A tire property file's model, in SI units, ISO/TYDEX-W coefficient signs.
/// Members carry the file's key names (the standard's), one per model key.
struct MagicFormulaCoefficients {
  std::string file;  ///< The file it was read from (for messages).
  /// 6 (PAC2002), 61 or 62 (MF 6.1, 6.2; both evaluated as 6.1). From FITTYP,
  /// else from PROPERTY_FILE_FORMAT ('PAC2002' -> 6, 'MF_61' -> 61, ...),
  /// else 61 (defaulted).
  int FITTYP = 61;
  /// The side the coefficients were measured for (TYRESIDE: 'LEFT', 'RIGHT'
  /// or 'SYMMETRIC'; default 'LEFT').
  TireSide TYRESIDE = TireSide::Left;
#define VDYN_MF_MEMBER(NAME, DIM, DEFAULT) double NAME = DEFAULT;
  VDYN_MF_KEYS(VDYN_MF_MEMBER)
#undef VDYN_MF_MEMBER
};

/// A parsed property file.
struct TirFile {
  MagicFormulaCoefficients coefficients;
  /// Model keys the file does not give, set to their defaults, in table order
  /// (for the run summary). FITTYP and TYRESIDE appear here when absent.
  std::vector<std::string> defaulted_keys;
  /// Keys of the format the file gives that this model does not use (turn
  /// slip, structural, contact-patch, ranges, inertia, header, ...).
  std::vector<std::string> unused_keys;
};

/// Reads the .tir file at `path` (Errors: see the top of this header; a file
/// that cannot be opened names the path).
TirFile readTirFile(const std::string& path);

/// Parses .tir text; `file` names it in error messages.
TirFile parseTirText(const std::string& text, const std::string& file);

}  // namespace vdyn::mf
