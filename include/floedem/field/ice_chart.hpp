#pragma once
// Ice from an ice chart (docs/ice_charts.md): the polygons of a chart in the WMO's SIGRID-3
// codes (a shapefile, GeoJSON or any vector file GDAL's OGR reads), each filled by the field
// generator with the concentration, floe sizes and thickness its codes give
// (field/sigrid3.hpp).
//
// Each polygon is projected onto the scene's plane, cut to the field's rectangle and cut free
// of the scene's bodies and keep-out zones (GEOS, through OGR); each piece left is filled on
// its own: the generator's domain is the piece's bounding box, and what of the box is not the
// piece (the pockets between the piece's outline and the box, and its holes) is kept out. A
// floe lies inside its own power cell, which lies inside its piece, so floes of neighbouring
// polygons never overlap, and each piece holds its polygon's concentration of its own area.
#include <cstdint>
#include <string>
#include <vector>

#include "floedem/field/field_generator.hpp"
#include "floedem/scene/geo.hpp"

namespace floedem {

/// One connected part of a chart polygon, on the scene's plane (m).
struct ChartPart {
  std::vector<Vec2> outer;                 ///< counter-clockwise
  std::vector<std::vector<Vec2>> holes;
};

/// One feature of the chart: its SIGRID-3 codes and what they give the generator.
struct ChartPolygon {
  std::int64_t fid = 0;   ///< the feature's id in the file (named in messages)
  int ct = 0;             ///< total concentration code
  int sa = -9;            ///< stage of development code (-9: not read, the polygon has no ice)
  int fa = -9;            ///< form of ice code (-9: likewise)
  double concentration = 0.0;  ///< the code's (the middle of an interval), in [0, 1]
  double d_min = 0.0, d_max = 0.0;              ///< m, equal-area diameters, from FA
  double thickness_min = 0.0, thickness_max = 0.0;  ///< m, from SA
  std::vector<ChartPart> parts;
};

struct IceChart {
  std::string path;
  std::string layer;
  std::vector<ChartPolygon> polygons;
};

/// Reads a chart whose coordinates are longitude and latitude (a file without a coordinate
/// reference system) or are in any reference system PROJ knows (transformed to WGS 84 first),
/// and projects it onto the scene's plane. `layer`: empty for the file's first. Edges are
/// divided to at most 0.01 deg before they are projected, so that a long straight edge in
/// degrees follows its true course on the plane. Throws InputError naming the file, the feature
/// and the attribute: a file OGR cannot open, a layer without CT, SA or FA, a geometry that is
/// not a valid polygon, a code that is not one of the tables', two polygons that overlap.
IceChart read_ice_chart(const std::string& path, const std::string& layer, const GeoProjection& geo);

/// What one chart polygon put into the field.
struct ChartPolygonStats {
  std::int64_t fid = 0;
  double area = 0.0;         ///< m^2 inside the field's rectangle
  double free_area = 0.0;    ///< m^2 of that, outside the bodies and keep-out zones
  double ice_area = 0.0;     ///< m^2 of floes
  std::size_t floes = 0;
  std::size_t pieces = 0;            ///< pieces filled
  std::size_t pieces_too_small = 0;  ///< pieces smaller than one floe of d_min at the concentration: left open
  double d_max_used = 0.0;   ///< m: FA's d_max, or less where the largest piece could not hold a cell of it
  PowerLawFit fit;           ///< exponent fitted to this polygon's floes (over all its pieces)
};

/// Fills every polygon of `chart` inside `base`'s rectangle, outside `base.keep_out`, with
/// `base`'s alpha, irregularity and seed (each piece its own stream, drawn from the seed) and
/// the polygon's concentration, size range and a thickness uniform over its stage's range.
/// A concentration of 10/10 is filled at FieldSpec::max_concentration. Where a piece cannot
/// hold the cell of a floe of d_max, its d_max is the largest that fits; a piece that cannot
/// hold one of d_min stays open water. Throws FieldSpecError ("chart") where the generator
/// refuses a piece. The same chart, spec and seed give the identical field.
Field generate_chart_field(const IceChart& chart, const FieldSpec& base, std::vector<ChartPolygonStats>& stats);

}  // namespace floedem
