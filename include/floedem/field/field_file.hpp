#pragma once
// A generated field as scene bodies, and as a field file: the /bodies layout of a run's
// output with one frame at t = 0 (written by the same Recorder), plus /field with the
// generator's parameters and what it achieved. io/output.hpp reads both.
#include <string>
#include <vector>

#include "floedem/field/field_generator.hpp"
#include "floedem/field/ice_chart.hpp"
#include "floedem/scene/scene.hpp"

namespace floedem {

/// The floes of a field as scene bodies named prefix + index, at rest, of the given density.
std::vector<BodySpec> field_floes(const Field& field, double density, const std::string& prefix = "field-");

/// The /field attributes: the generator's parameters and what it achieved (a field file's and a
/// run's output with a generated [field] alike). `first_floe`: the index of the field's first
/// body (0 in a field file; after the scenario's own [[body]] entries in a run).
Provenance field_provenance(const Field& field, const FieldSpec& spec, double density, std::size_t first_floe);

/// The /field attributes of a field from an ice chart, and one group per chart polygon
/// (/field/chart_feature_FID: its codes, what they gave the generator, what it made).
std::vector<Provenance> chart_provenance(const Field& field, const IceChart& chart, const std::vector<ChartPolygonStats>& stats,
                                         const FieldSpec& spec, double density, std::size_t first_floe);

/// Writes FIELD.h5 (under FIELD.h5.partial until complete). Throws OutputError.
void write_field_file(const std::string& path, const Field& field, const FieldSpec& spec, double density,
                      const std::string& floedem_version);

/// The thickness distribution in words, for attributes and messages ("1.16 m", ...).
std::string describe(const ThicknessDistribution& t);

}  // namespace floedem
