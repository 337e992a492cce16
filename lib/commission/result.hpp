// SPDX-License-Identifier: GPL-2.0-or-later
// What the commutation analysis found: each value with its uncertainty and a line saying how
// it was found, or a problem saying why it could not be told.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "commission/hall_table.hpp"

namespace i20::commission {

template <class T>
struct Finding {
  T value{};
  // A bound on the error, in the value's unit (about three standard deviations plus the
  // encoder's quantisation); 0 for a value given by the user or an exact count.
  double uncertainty = 0;
  std::string how;  // one line
};

enum class ProblemKind {
  NotEnoughSamples,
  SweepTooShort,                        // less than one electrical turn each way
  NoMotion,                             // stall: neither the encoder nor the Hall sensors moved
  EncoderSilent,                        // the Hall sensors changed but the encoder did not count
  MoveDisagreesWithCommand,             // did not reverse with the command, or slipped
  InconsistentCountsPerElectricalTurn,  // forward and backward disagree
  CountsPerTurnMismatch,                // the given pole pairs and counts per turn disagree with the move
  PolePairsNotInteger,                  // counts per turn / counts per electrical turn is not a whole number
  NeedPolePairsOrCounts,                // neither given and no two index latches a turn apart
  CountsPerTurnInexact,                 // estimated, not exact: bldc's scale needs it exactly
  NoIndex,                              // no index latch during the sweep
  IndexInconsistent,                    // index latches that are not whole turns apart
  HallStuck,                            // a sensor never changed
  HallNoisy,                            // a sensor disagrees with its own half-turn pattern away from edges
  FewerThanSixHallStates,
  MoreThanSixHallStates,
  HallUnusedNotComplementary,
  HallOrderInconsistent,  // the states do not follow each other one sensor at a time
  HallEdgeMissing,
  HallBetweenSectors,    // the states sit about half way between bldc's sector centres
  HallLayoutUnexpected,  // differs from the hint
  PatternNumberUnknown,  // the map is not one of bldc(9)'s 48 (cannot happen for a Gray six-cycle)
};

struct Problem {
  ProblemKind kind;
  std::string message;
};

enum class SensorCondition { Ok, StuckHigh, StuckLow, Noisy };

struct HallSensorFinding {
  int sensor = 1;  // 1-3, bldc's hall1..hall3
  SensorCondition condition = SensorCondition::Ok;
  double wrong_fraction = 0;   // samples away from its edges that disagree with its arc
  double high_centre_deg = 0;  // electrical angle of the middle of its high half-turn
  std::string how;
};

struct HallStateAngle {
  HallCode code = 0;
  Finding<double> centre_deg;  // middle of the state's sector, electrical degrees [0, 360)
  int bldc_sector = 0;         // k: the state stands for bldc's sector centred on k*60 degrees
};

struct HallEdgeAngle {
  HallCode before = 0;  // the state below the edge (in increasing electrical angle)
  HallCode after = 0;
  Finding<double> angle_deg;
  // Half the gap between the forward and backward crossings (against the encoder angle the
  // play between rotor and encoder counts against it).
  double hysteresis_deg = 0;
};

struct HallFindings {
  std::vector<HallSensorFinding> sensors;  // three, once the Hall sensors were judged
  std::vector<HallStateAngle> states;      // in increasing electrical angle, when six were found
  std::vector<HallEdgeAngle> edges;        // edges[k] follows states[k]
  std::optional<Finding<HallSequence>> sequence;
  std::optional<std::size_t> table_row;  // index into hall_table()
  std::optional<Finding<HallLayout>> layout;
  int middle_sensor_of_60 = 0;  // 60-degree layout: the sensor whose inversion gives 120
  // How far the states sit from bldc's sector centres (electrical degrees, signed).
  std::optional<Finding<double>> offset_from_bldc_sectors_deg;
  std::optional<Finding<int>> bldc_pattern;  // only where bldc's numbering is known
  std::optional<HallRewiring> rewiring_to_25;
};

struct CommutationResult {
  std::optional<Finding<int>> encoder_direction;              // +1 counts up going forward; bldc scale's sign
  std::optional<Finding<double>> counts_per_electrical_turn;  // magnitude
  std::optional<Finding<int>> pole_pairs;
  std::optional<Finding<double>> counts_per_turn;  // mechanical
  // Electrical angle (degrees, [0, 360)) of the rotor when the index latches.
  std::optional<Finding<double>> index_electrical_angle_deg;
  // bldc's `encoder-offset` for qi/qhi: counts from the index to electrical zero, in the
  // encoder's counting direction, in [0, counts per electrical turn).
  std::optional<Finding<std::int64_t>> encoder_offset_counts;
  // The same distance in electrical degrees.
  std::optional<Finding<double>> encoder_offset_deg;
  std::optional<Finding<double>> friction_lag_deg;  // how far the rotor trailed the command
  HallFindings hall;
  std::vector<Problem> problems;   // what could not be told, and why
  std::vector<std::string> notes;  // warnings that did not stop a value

  bool has(ProblemKind kind) const;
};

}  // namespace i20::commission
