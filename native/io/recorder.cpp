#include "io/recorder.hpp"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/statvfs.h>

#include <H5Cpp.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "floedem/engine/state_io.hpp"
#include "floedem/scene/geo.hpp"
#include "floedem/scene/input_error.hpp"
#include "floedem/version.hpp"
#include "io/h5_read.hpp"

namespace floedem {

namespace {

/// H5Fflush, with the file's space reserved first. A flush writes the superblock, which holds
/// the address where the file ends (its EOA), in the same pass as the cached metadata and
/// chunks that it gives space past the old end. On a full disk or under a file-size limit the
/// superblock at the front was written and the writes past the end failed: the file on disk
/// was then shorter than its superblock said, and HDF5 refused to open it ("truncated file"),
/// so a run stopped by a full disk could not be resumed. (Flushing each dataset first does not
/// do: H5Dflush writes the chunk index in place, pointing past the superblock's end.) So the
/// space a flush can take is reserved first (posix_fallocate): the EOA, every open dataset's
/// cached chunks (flush_bound: a chunk gets its space when it leaves the chunk cache), the
/// metadata cache, and a little room. A failure then comes before anything is
/// written, and the file stays as its last flush left it: the state a kill leaves, which
/// --resume continues. HDF5 cuts the file back to its EOA when it closes it.
/// The most file space that flushing dataset `d` can take: the chunks its chunk cache holds,
/// at most the cache's size and at most the dataset's whole size (in whole chunks). Not what
/// it has been given (H5Dget_storage_size): asking flushes the cache, past the reservation.
haddr_t flush_bound(hid_t d) {
  const hid_t space = H5Dget_space(d), create = H5Dget_create_plist(d), access = H5Dget_access_plist(d),
              type = H5Dget_type(d);
  const int rank = space < 0 ? -1 : H5Sget_simple_extent_ndims(space);
  const std::size_t element = type < 0 ? 0 : H5Tget_size(type);
  std::size_t slots = 0, cache = 0;
  double w0 = 0.0;
  haddr_t whole = 0;
  bool known = rank >= 0 && create >= 0 && element > 0 && access >= 0 &&
               H5Pget_chunk_cache(access, &slots, &cache, &w0) >= 0;
  if (known) {
    std::vector<hsize_t> dims(static_cast<std::size_t>(rank)), chunk(static_cast<std::size_t>(rank), 0);
    known = H5Sget_simple_extent_dims(space, dims.data(), nullptr) == rank;
    const bool chunked = H5Pget_layout(create) == H5D_CHUNKED && H5Pget_chunk(create, rank, chunk.data()) == rank;
    whole = element;
    for (std::size_t k = 0; k < dims.size(); ++k) {
      const hsize_t c = std::max<hsize_t>(chunked ? chunk[k] : dims[k], 1);
      whole *= (dims[k] + c - 1) / c * c;
    }
    if (chunked) whole = std::min<haddr_t>(whole, cache);
  }
  if (space >= 0) H5Sclose(space);
  if (create >= 0) H5Pclose(create);
  if (access >= 0) H5Pclose(access);
  if (type >= 0) H5Tclose(type);
  if (!known) throw H5::FileIException("H5Fflush", "cannot read a dataset's shape");
  return whole;
}

void flush_with_room(H5::H5File& file) {
  const hid_t id = file.getId();
  haddr_t bound = 0;
  if (H5Fget_eoa(id, &bound) < 0) throw H5::FileIException("H5Fflush", "cannot find the file's end");
  const unsigned types = H5F_OBJ_DATASET | H5F_OBJ_LOCAL;
  const ssize_t count = H5Fget_obj_count(id, types);
  std::vector<hid_t> datasets(static_cast<std::size_t>(std::max<ssize_t>(count, 0)));
  if (count < 0 || H5Fget_obj_ids(id, types, datasets.size(), datasets.data()) < 0)
    throw H5::FileIException("H5Fflush", "cannot list the open datasets");
  for (const hid_t d : datasets) bound += flush_bound(d);
  std::size_t max_size = 0, min_clean = 0, cached = 0;
  int entries = 0;
  if (H5Fget_mdc_size(id, &max_size, &min_clean, &cached, &entries) < 0)
    throw H5::FileIException("H5Fflush", "cannot read the metadata cache's size");
  bound += cached + (haddr_t{1} << 16);
  void* handle = nullptr;
  if (H5Fget_vfd_handle(id, H5P_DEFAULT, &handle) < 0 || !handle)
    throw H5::FileIException("H5Fflush", "cannot find the file's descriptor");
  const int error = posix_fallocate(*static_cast<const int*>(handle), 0, static_cast<off_t>(bound));
  if (error != 0) throw H5::FileIException("H5Fflush", std::string("no room to flush: ") + std::strerror(error));
  file.flush(H5F_SCOPE_GLOBAL);
}

}  // namespace

// Not in the anonymous namespace: Series is a member type of Recorder::Impl, which has external
// linkage, and a unity build (scripts/test.sh) that batches this file with others would then
// give Impl a field of internal linkage from another file than the batch's (-Wsubobject-linkage).
namespace recorder_detail {

/// A dataset that grows along its first dimension: [rows, shape...].
class Series {
 public:
  Series() = default;
  Series(H5::Group& parent, const std::string& name, const H5::DataType& type, std::vector<hsize_t> row_shape,
         hsize_t chunk_rows)
      : type_(type), row_shape_(std::move(row_shape)) {
    std::vector<hsize_t> dims{0}, maxdims{H5S_UNLIMITED}, chunk{std::max<hsize_t>(chunk_rows, 1)};
    for (const hsize_t d : row_shape_) {
      dims.push_back(d);
      maxdims.push_back(d);
      chunk.push_back(std::max<hsize_t>(d, 1));
    }
    H5::DataSpace space(static_cast<int>(dims.size()), dims.data(), maxdims.data());
    H5::DSetCreatPropList plist;
    plist.setChunk(static_cast<int>(chunk.size()), chunk.data());
    H5Pset_obj_track_times(plist.getId(), false);  // no timestamps: identical runs, identical files
    dataset_ = parent.createDataSet(name, type_, space, plist);
  }

  /// An existing table (a resumed run), written with the memory type `type`.
  Series(H5::DataSet dataset, const H5::DataType& type) : dataset_(std::move(dataset)), type_(type) {
    const H5::DataSpace space = dataset_.getSpace();
    std::vector<hsize_t> dims(static_cast<std::size_t>(space.getSimpleExtentNdims()));
    space.getSimpleExtentDims(dims.data());
    rows_ = dims.at(0);
    row_shape_.assign(dims.begin() + 1, dims.end());
  }

  /// Cuts the table back to its first `rows` rows.
  void truncate(hsize_t rows, const std::string& name) {
    if (rows > rows_)
      throw InputError(name + " has " + std::to_string(rows_) + " rows, fewer than the checkpoint's " +
                       std::to_string(rows) + ": the file was changed after the run");
    std::vector<hsize_t> dims{rows};
    dims.insert(dims.end(), row_shape_.begin(), row_shape_.end());
    if (H5Dset_extent(dataset_.getId(), dims.data()) < 0) throw H5::DataSetIException("truncate", name);
    rows_ = rows;
  }

  void append(const void* data, hsize_t rows) {
    if (rows == 0) return;
    std::vector<hsize_t> dims{rows_ + rows}, start{rows_}, count{rows};
    for (const hsize_t d : row_shape_) {
      dims.push_back(d);
      start.push_back(0);
      count.push_back(d);
    }
    dataset_.extend(dims.data());
    H5::DataSpace file_space = dataset_.getSpace();
    file_space.selectHyperslab(H5S_SELECT_SET, count.data(), start.data());
    H5::DataSpace memory(static_cast<int>(count.size()), count.data());
    dataset_.write(data, type_, memory, file_space);
    rows_ += rows;
  }
  hsize_t rows() const { return rows_; }
  H5::DataSet& dataset() { return dataset_; }

 private:
  H5::DataSet dataset_;
  H5::DataType type_;
  std::vector<hsize_t> row_shape_;
  hsize_t rows_ = 0;
};

}  // namespace recorder_detail

using recorder_detail::Series;

namespace {

H5::DSetCreatPropList fixed_plist() {
  H5::DSetCreatPropList plist;
  H5Pset_obj_track_times(plist.getId(), false);
  return plist;
}

template <class T>
void write_fixed(H5::Group& g, const std::string& name, const H5::DataType& type, const std::vector<T>& data,
                 std::vector<hsize_t> dims) {
  H5::DataSpace space(static_cast<int>(dims.size()), dims.data());
  H5::DataSet ds = g.createDataSet(name, type, space, fixed_plist());
  if (!data.empty()) ds.write(data.data(), type);
}

// A string as format 2 stores it: fixed-length, its own length (at least one byte), padded with
// NULs, so that no reader goes through HDF5's global heap, whose damaged objects Debian's HDF5
// reads out of bounds. Format 1 (a run written before, continued by --resume) keeps
// variable-length strings, as its readers expect.
H5::StrType string_type(std::size_t longest, bool fixed) {
  H5::StrType type(H5::PredType::C_S1, fixed ? std::max<std::size_t>(1, longest) : H5T_VARIABLE);
  if (fixed) type.setStrpad(H5T_STR_NULLPAD);
  type.setCset(H5T_CSET_UTF8);
  return type;
}

void write_text(H5::H5Object& obj, const std::string& name, const std::string& value, bool fixed) {
  const H5::StrType type = string_type(value.size(), fixed);
  if (obj.attrExists(name)) {
    H5::Attribute old = obj.openAttribute(name);
    if (old.getDataType() == type) {
      old.write(type, value);
      return;
    }
    old.close();
    obj.removeAttr(name);  // another length: made again
  }
  H5::Attribute a = obj.createAttribute(name, type, H5::DataSpace(H5S_SCALAR));
  a.write(type, value);
}

template <class T>
void write_number_attribute(H5::H5Object& obj, const std::string& name, const H5::PredType& type, T value) {
  H5::Attribute a = obj.attrExists(name) ? obj.openAttribute(name) : obj.createAttribute(name, type, H5::DataSpace(H5S_SCALAR));
  a.write(type, &value);
}

void write_attribute(H5::H5Object& obj, const std::string& name, double value) {
  write_number_attribute(obj, name, H5::PredType::NATIVE_DOUBLE, value);
}

H5::EnumType contact_kind_type() {
  H5::EnumType t(H5::PredType::NATIVE_UINT8);
  std::uint8_t v = static_cast<std::uint8_t>(ContactKind::collision);
  t.insert("collision", &v);
  v = static_cast<std::uint8_t>(ContactKind::resting);
  t.insert("resting", &v);
  return t;
}

std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : sep) + s;
  return out;
}

/// Frames per chunk: about 64 K values, so that tiny scenes do not pay per-frame overhead.
hsize_t frame_chunk_of(std::size_t bodies) {
  const hsize_t per_frame = 2 * std::max<std::size_t>(bodies, 1);
  return std::clamp<hsize_t>(65536 / per_frame, 1, 4096);
}

}  // namespace

std::uint64_t slot_checksum(std::int64_t step, const std::vector<std::uint8_t>& state) {
  std::uint64_t h = state_checksum(state.data(), state.size());
  return h ^ state_checksum(reinterpret_cast<const std::uint8_t*>(&step), sizeof step);
}

struct Recorder::Impl {
  H5::H5File file;
  // The file's layout: this floedem's, or a format 1 run's that --resume continues as it is.
  std::int64_t format = kOutputFormatVersion;
  bool fixed_strings = true;  // format 2 on: every string fixed-length (string_type)
  std::size_t bodies = 0;
  // Frames.
  Series time, position, angle, velocity, angular_velocity;
  hsize_t frame_chunk = 1;
  std::vector<double> b_time, b_position, b_angle, b_velocity, b_angular_velocity;
  hsize_t buffered_frames = 0;
  // A geographic scene's longitude and latitude of each body per frame (docs/geography.md).
  std::unique_ptr<GeoProjection> geo;
  Series lonlat;
  std::vector<double> b_lonlat;
  // Contacts.
  Series c_time, c_body_a, c_body_b, c_point, c_normal, c_normal_impulse, c_tangent_impulse, c_approach, c_separation,
      c_kind;
  std::vector<double> k_time, k_point, k_normal, k_normal_impulse, k_tangent_impulse, k_approach, k_separation;
  std::vector<std::int32_t> k_body_a, k_body_b;
  std::vector<std::uint8_t> k_kind;
  H5::EnumType kind_type = contact_kind_type();
  // Collision events.
  Series e_time, e_body_a, e_body_b, e_impulse, e_mass, e_approach, e_restitution, e_duration, e_mean, e_peak,
      e_width, e_crushed;
  std::vector<CollisionRow> events;
  ContactOutput contact_output = ContactOutput::all;
  // Towing.
  bool tow = false;
  bool rope = false, tug = false;  // the tow's rope (modes rope, tug) and its tug (mode tug)
  void set_tow(const TowSpec& spec) {
    tow = spec.mode != TowSpec::Mode::none;
    rope = spec.has_rope();
    tug = spec.mode == TowSpec::Mode::tug;
  }
  bool crushing = false;  // contact.force_model = pressure_area: two more collision columns
  Series tow_time, tow_force, tow_force_mean, tow_ice_mean, tow_tug, tow_tension, tow_tug_velocity;
  std::vector<double> w_time, w_force, w_mean, w_ice, w_tug, w_tension, w_tug_velocity;
  // Contact loads.
  Series load_time, load_force;
  std::vector<double> l_time, l_force;
  bool closed = false;
  bool write_failed = false;

  /// A growing table: where it lives, the type it is written with, its row shape, rows per
  /// chunk, and the count of RecordedRows that says how many rows it has.
  struct Table {
    Series* series;
    const char* path;
    H5::DataType type;
    std::vector<hsize_t> row_shape;
    hsize_t chunk;
    std::int64_t RecordedRows::*rows;
  };

  /// Every growing table of the scene's file, in one list for creating them (a new run) and for
  /// reopening and cutting them back (a resumed run). frame_chunk and tow must be set.
  std::vector<Table> tables(const Scene& scene) {
    const H5::PredType& f64 = H5::PredType::NATIVE_DOUBLE;
    const H5::PredType& i32 = H5::PredType::NATIVE_INT32;
    const hsize_t n = bodies;
    constexpr hsize_t kc = 4096, ke = 1024, kt = 1024;  // /tow and /loads may be written every step
    using R = RecordedRows;
    std::vector<Table> t = {
        {&time, "/time", f64, {}, std::max<hsize_t>(frame_chunk, 256), &R::frames},
        {&position, "/bodies/position", f64, {n, 2}, frame_chunk, &R::frames},
        {&angle, "/bodies/angle", f64, {n}, frame_chunk, &R::frames},
        {&velocity, "/bodies/velocity", f64, {n, 2}, frame_chunk, &R::frames},
        {&angular_velocity, "/bodies/angular_velocity", f64, {n}, frame_chunk, &R::frames},
    };
    if (scene.geo.present) t.push_back({&lonlat, "/bodies/lonlat", f64, {n, 2}, frame_chunk, &R::frames});
    t.insert(t.end(), {
        {&c_time, "/contacts/time", f64, {}, kc, &R::contacts},
        {&c_body_a, "/contacts/body_a", i32, {}, kc, &R::contacts},
        {&c_body_b, "/contacts/body_b", i32, {}, kc, &R::contacts},
        {&c_point, "/contacts/point", f64, {2}, kc, &R::contacts},
        {&c_normal, "/contacts/normal", f64, {2}, kc, &R::contacts},
        {&c_normal_impulse, "/contacts/normal_impulse", f64, {}, kc, &R::contacts},
        {&c_tangent_impulse, "/contacts/tangent_impulse", f64, {}, kc, &R::contacts},
        {&c_approach, "/contacts/approach_velocity", f64, {}, kc, &R::contacts},
        {&c_separation, "/contacts/separation", f64, {}, kc, &R::contacts},
        {&c_kind, "/contacts/kind", kind_type, {}, kc, &R::contacts},
        {&e_time, "/contacts/collisions/time", f64, {}, ke, &R::collisions},
        {&e_body_a, "/contacts/collisions/body_a", i32, {}, ke, &R::collisions},
        {&e_body_b, "/contacts/collisions/body_b", i32, {}, ke, &R::collisions},
        {&e_impulse, "/contacts/collisions/normal_impulse", f64, {}, ke, &R::collisions},
        {&e_mass, "/contacts/collisions/effective_mass", f64, {}, ke, &R::collisions},
        {&e_approach, "/contacts/collisions/approach_speed", f64, {}, ke, &R::collisions},
        {&e_restitution, "/contacts/collisions/restitution_achieved", f64, {}, ke, &R::collisions},
        {&e_duration, "/contacts/collisions/duration", f64, {}, ke, &R::collisions},
        {&e_mean, "/contacts/collisions/mean_force", f64, {}, ke, &R::collisions},
        {&e_peak, "/contacts/collisions/peak_force", f64, {}, ke, &R::collisions},
    });
    if (scene.contact.force_model == ContactSettings::ForceModel::pressure_area) {
      t.push_back({&e_width, "/contacts/collisions/contact_width", f64, {}, ke, &R::collisions});
      t.push_back({&e_crushed, "/contacts/collisions/crushed", H5::PredType::NATIVE_UINT8, {}, ke, &R::collisions});
    }
    if (tow) {
      t.push_back({&tow_time, "/tow/time", f64, {}, kt, &R::tow});
      t.push_back({&tow_force, "/tow/force", f64, {2}, kt, &R::tow});
      t.push_back({&tow_force_mean, "/tow/force_mean", f64, {2}, kt, &R::tow});
      t.push_back({&tow_ice_mean, "/tow/ice_force_mean", f64, {2}, kt, &R::tow});
      t.push_back({&tow_tug, "/tow/tug_position", f64, {2}, kt, &R::tow});
      if (rope) t.push_back({&tow_tension, "/tow/tension_max", f64, {}, kt, &R::tow});
      if (tug) t.push_back({&tow_tug_velocity, "/tow/tug_velocity", f64, {2}, kt, &R::tow});
    }
    if (!scene.output.load_bodies.empty()) {
      const hsize_t nb = scene.output.load_bodies.size();
      t.push_back({&load_time, "/loads/time", f64, {}, kt, &R::loads});
      t.push_back({&load_force, "/loads/force", f64, {nb, 2}, kt, &R::loads});
    }
    return t;
  }

  void write_buffers() {
    if (buffered_frames > 0) {
      time.append(b_time.data(), buffered_frames);
      position.append(b_position.data(), buffered_frames);
      angle.append(b_angle.data(), buffered_frames);
      velocity.append(b_velocity.data(), buffered_frames);
      angular_velocity.append(b_angular_velocity.data(), buffered_frames);
      if (geo) lonlat.append(b_lonlat.data(), buffered_frames);
      b_lonlat.clear();
      b_time.clear(); b_position.clear(); b_angle.clear(); b_velocity.clear(); b_angular_velocity.clear();
      buffered_frames = 0;
    }
    if (!w_time.empty()) {
      const hsize_t n = w_time.size();
      tow_time.append(w_time.data(), n);
      tow_force.append(w_force.data(), n);
      tow_force_mean.append(w_mean.data(), n);
      tow_ice_mean.append(w_ice.data(), n);
      tow_tug.append(w_tug.data(), n);
      if (rope) tow_tension.append(w_tension.data(), n);
      if (tug) tow_tug_velocity.append(w_tug_velocity.data(), n);
      w_time.clear(); w_force.clear(); w_mean.clear(); w_ice.clear(); w_tug.clear(); w_tension.clear();
      w_tug_velocity.clear();
    }
    if (!l_time.empty()) {
      load_time.append(l_time.data(), l_time.size());
      load_force.append(l_force.data(), l_time.size());
      l_time.clear(); l_force.clear();
    }
    const hsize_t rows = k_time.size();
    if (rows > 0) {
      c_time.append(k_time.data(), rows);
      c_body_a.append(k_body_a.data(), rows);
      c_body_b.append(k_body_b.data(), rows);
      c_point.append(k_point.data(), rows);
      c_normal.append(k_normal.data(), rows);
      c_normal_impulse.append(k_normal_impulse.data(), rows);
      c_tangent_impulse.append(k_tangent_impulse.data(), rows);
      c_approach.append(k_approach.data(), rows);
      c_separation.append(k_separation.data(), rows);
      c_kind.append(k_kind.data(), rows);
      k_time.clear(); k_body_a.clear(); k_body_b.clear(); k_point.clear(); k_normal.clear();
      k_normal_impulse.clear(); k_tangent_impulse.clear(); k_approach.clear(); k_separation.clear(); k_kind.clear();
    }
    if (!events.empty()) {
      const hsize_t n = events.size();
      auto column = [&](Series& s, auto member) {
        using T = std::remove_cvref_t<decltype(events[0].*member)>;
        std::vector<T> v;
        v.reserve(n);
        for (const CollisionRow& r : events) v.push_back(r.*member);
        s.append(v.data(), n);
      };
      column(e_time, &CollisionRow::time);
      column(e_body_a, &CollisionRow::body_a);
      column(e_body_b, &CollisionRow::body_b);
      column(e_impulse, &CollisionRow::normal_impulse);
      column(e_mass, &CollisionRow::effective_mass);
      column(e_approach, &CollisionRow::approach_speed);
      column(e_restitution, &CollisionRow::restitution_achieved);
      column(e_duration, &CollisionRow::duration);
      column(e_mean, &CollisionRow::mean_force);
      column(e_peak, &CollisionRow::peak_force);
      if (crushing) {
        column(e_width, &CollisionRow::contact_width);
        column(e_crushed, &CollisionRow::crushed);
      }
      events.clear();
    }
  }

  /// Writes the buffers and flushes HDF5, so that what is written stays readable if the
  /// run is killed. Called when a buffer fills (points fixed by the data) and at the end,
  /// never on the clock: the file's layout, and so its bytes, then do not depend on how fast
  /// the run went (a flush at a clock-chosen moment moves HDF5's allocations).
  void flush() {
    write_buffers();
    flush_with_room(file);
  }
};

Recorder::Recorder(const std::string& path, const Scene& scene, const EngineInfo& engine, const RunInfo& run)
    : lock_(std::make_unique<OutputLock>(path)), impl_(std::make_unique<Impl>()), path_(path), partial_path_(path + ".partial") {
  H5::Exception::dontPrint();
  check_space(scene);
  try {
    Impl& d = *impl_;
    d.file = H5::H5File(partial_path_, H5F_ACC_TRUNC);
    H5::Group root = d.file.openGroup("/");
    write_text(root, "status", "running", d.fixed_strings);
    write_text(root, "engine", engine.name, d.fixed_strings);
    write_text(root, "engine_version", engine.version, d.fixed_strings);
    write_run_attributes(scene, run);

    H5::Group eng = d.file.createGroup("/engine");
    for (const auto& [k, v] : engine.settings) write_text(eng, k, v, d.fixed_strings);
    write_text(eng, "limitations", join(engine.limitations, "\n"), d.fixed_strings);

    // Bodies: what does not change.
    const std::size_t n = scene.bodies.size();
    d.bodies = n;
    H5::Group bodies = d.file.createGroup("/bodies");
    {
      std::size_t longest = 0;
      for (const auto& b : scene.bodies) longest = std::max(longest, b.name.size());
      const H5::StrType type = string_type(longest, true);
      std::vector<char> names(n * type.getSize(), '\0');  // each name in its slot, NUL-padded
      for (std::size_t i = 0; i < n; ++i) std::copy(scene.bodies[i].name.begin(), scene.bodies[i].name.end(), &names[i * type.getSize()]);
      write_fixed(bodies, "name", type, names, {n});
    }
    std::vector<double> mass, inertia, area, thickness, density;
    std::vector<std::uint8_t> fixed;
    std::vector<double> vertices;
    std::vector<std::int64_t> offsets{0};
    for (const auto& b : scene.bodies) {
      mass.push_back(b.mass);
      inertia.push_back(b.inertia);
      area.push_back(b.area);
      thickness.push_back(b.thickness);
      density.push_back(b.density);
      fixed.push_back(b.fixed ? 1 : 0);
      for (const Vec2 v : b.local_polygon) {
        vertices.push_back(v.x);
        vertices.push_back(v.y);
      }
      offsets.push_back(static_cast<std::int64_t>(vertices.size() / 2));
    }
    write_fixed(bodies, "mass", H5::PredType::NATIVE_DOUBLE, mass, {n});
    write_fixed(bodies, "inertia", H5::PredType::NATIVE_DOUBLE, inertia, {n});
    write_fixed(bodies, "area", H5::PredType::NATIVE_DOUBLE, area, {n});
    write_fixed(bodies, "thickness", H5::PredType::NATIVE_DOUBLE, thickness, {n});
    write_fixed(bodies, "density", H5::PredType::NATIVE_DOUBLE, density, {n});
    write_fixed(bodies, "fixed", H5::PredType::NATIVE_UINT8, fixed, {n});
    write_fixed(bodies, "polygon_vertices", H5::PredType::NATIVE_DOUBLE, vertices, {vertices.size() / 2, 2});
    write_fixed(bodies, "polygon_offsets", H5::PredType::NATIVE_INT64, offsets, {n + 1});

    H5::Group contacts = d.file.createGroup("/contacts");
    const char* which = scene.output.contacts == ContactOutput::all ? "all"
                        : scene.output.contacts == ContactOutput::collisions ? "collisions" : "none";
    write_text(contacts, "recorded", which, d.fixed_strings);
    d.contact_output = scene.output.contacts;
    H5::Group events = d.file.createGroup("/contacts/collisions");
    write_attribute(events, "duration_coefficient", scene.contact.duration_coefficient);
    d.crushing = scene.contact.force_model == ContactSettings::ForceModel::pressure_area;
    write_text(events, "duration_model",
               d.crushing ? "estimated from the impulse: the pulse of the linear spring capped by the crushing force "
                            "over the nominal contact area (docs/model.md 4)"
                          : describe(duration_model_of(engine)),
               d.fixed_strings);
    if (d.crushing) {
      // Only then, so that the linear model's files keep their bytes.
      write_text(events, "force_model", "pressure_area", d.fixed_strings);
      write_attribute(events, "crushing_coefficient", scene.contact.crushing_coefficient);
      write_attribute(events, "crushing_width_exponent", scene.contact.crushing_width_exponent);
      write_text(events, "crushing_thickness_exponent",
                 scene.contact.has_crushing_thickness_exponent
                     ? setting_text(scene.contact.crushing_thickness_exponent)
                     : "min(-0.3, 0.2 h - 0.5), h in m (ISO 19906)",
                 d.fixed_strings);
    }
    d.set_tow(scene.tow);
    if (d.tow) {
      H5::Group tow = d.file.createGroup("/tow");
      write_text(tow, "mode", scene.tow.mode_name(), d.fixed_strings);
      write_text(tow, "body", scene.bodies[scene.tow.body].name, d.fixed_strings);
    }
    if (!scene.output.load_bodies.empty()) {
      H5::Group loads = d.file.createGroup("/loads");
      std::vector<std::int32_t> load_ids;
      for (const std::size_t i : scene.output.load_bodies) load_ids.push_back(static_cast<std::int32_t>(i));
      write_fixed(loads, "body", H5::PredType::NATIVE_INT32, load_ids, {load_ids.size()});
    }
    if (scene.geo.present) {
      d.geo = std::make_unique<GeoProjection>(scene.geo);
      H5::Group geo = d.file.createGroup("/geo");
      write_attribute(geo, "origin_lon", scene.geo.origin_lon);
      write_attribute(geo, "origin_lat", scene.geo.origin_lat);
      write_text(geo, "projection", scene.geo.projection, d.fixed_strings);
    }
    d.frame_chunk = frame_chunk_of(n);
    for (const Impl::Table& t : d.tables(scene)) *t.series = Series(root, t.path, t.type, t.row_shape, t.chunk);
    if (!scene.input_files.empty()) {  // only then: a scene that reads no file keeps its bytes
      H5::Group inputs = d.file.createGroup("/inputs");
      for (const InputFile& f : scene.input_files) write_text(inputs, f.key, f.text(), d.fixed_strings);
    }
    for (const Provenance& p : scene.provenance) {
      H5::Group g = d.file.createGroup(p.group);
      for (const auto& [k, v] : p.text) write_text(g, k, v, d.fixed_strings);
      for (const auto& [k, v] : p.numbers) write_attribute(g, k, v);
    }
    d.flush();
  } catch (const H5::Exception& e) {
    std::error_code ec;
    std::filesystem::remove(partial_path_, ec);
    // The datasets' handles cannot be closed after a failed write either (see ~Recorder): left
    // to the end of the process, so that the one-line error is all stderr gets.
    static_cast<void>(impl_.release());
    throw OutputError(partial_path_ + ": cannot create output file (" + e.getDetailMsg() +
                      "); is the directory there, writable and not full?");
  }
}

void Recorder::write_run_attributes(const Scene& scene, const RunInfo& run) {
  H5::Group root = impl_->file.openGroup("/");
  const bool fixed = impl_->fixed_strings;
  write_number_attribute(root, "format_version", H5::PredType::NATIVE_INT64, impl_->format);
  write_text(root, "floedem_version", run.floedem_version, fixed);
  write_text(root, "scenario", scene.source_text, fixed);
  write_text(root, "scenario_path", scene.source_path, fixed);
  write_text(root, "overrides", join(scene.overrides, "\n"), fixed);
  write_attribute(root, "dt", scene.run.dt);
  write_attribute(root, "duration", scene.run.duration);
  write_attribute(root, "output_every", static_cast<double>(scene.run.output_every));
  write_text(root, "forcing_terms", join(run.forcing_terms, ", "), fixed);
}

Recorder::Recorder(const std::string& path, const Scene& scene, const RunInfo& run, const RecordedRows& rows)
    : lock_(std::make_unique<OutputLock>(path)), impl_(std::make_unique<Impl>()), path_(path), partial_path_(path + ".partial") {
  namespace fs = std::filesystem;
  H5::Exception::dontPrint();
  const std::int64_t format = check_tables(fs::exists(partial_path_) ? partial_path_ : path_, scene, rows);
  impl_->format = format;
  impl_->fixed_strings = format >= 2;
  // A finished run being continued is no longer complete: it goes back under .partial first.
  if (!fs::exists(partial_path_)) {
    std::error_code ec;
    fs::rename(path_, partial_path_, ec);
    if (ec) throw OutputError(path_ + ": cannot rename to " + partial_path_ + " to continue the run: " + ec.message());
  }
  check_space(scene);
  Impl& d = *impl_;
  try {
    d.file = H5::H5File(partial_path_, H5F_ACC_RDWR);
    H5::Group root = d.file.openGroup("/");
    write_text(root, "status", "running", d.fixed_strings);
    std::vector<std::string> summary;
    for (int k = 0; k < root.getNumAttrs(); ++k) {
      const std::string name = root.openAttribute(static_cast<unsigned>(k)).getName();
      if (name.rfind("summary_", 0) == 0) summary.push_back(name);
    }
    for (const std::string& name : summary) root.removeAttr(name);
    write_run_attributes(scene, run);
    d.bodies = scene.bodies.size();
    d.frame_chunk = frame_chunk_of(d.bodies);
    d.contact_output = scene.output.contacts;
    d.set_tow(scene.tow);
    d.crushing = scene.contact.force_model == ContactSettings::ForceModel::pressure_area;
    if (scene.geo.present) d.geo = std::make_unique<GeoProjection>(scene.geo);
    for (const Impl::Table& t : d.tables(scene)) {
      *t.series = Series(d.file.openDataSet(t.path), t.type);
      t.series->truncate(static_cast<hsize_t>(rows.*t.rows), partial_path_ + ": " + t.path);
    }
    d.flush();
  } catch (const H5::Exception& e) {
    throw OutputError(partial_path_ + ": cannot reopen the run's file to continue it (" + e.getDetailMsg() + ")");
  }
}

void Recorder::write_checkpoint(std::int64_t index, std::int64_t step, const std::vector<std::uint8_t>& state) {
  write_slot(kCheckpointSlots[index % 2], step, state);
  // A regular checkpoint supersedes a stopped run's: dropped only now that this one is whole.
  drop_stop_checkpoint();
}

void Recorder::write_stop_checkpoint(std::int64_t step, const std::vector<std::uint8_t>& state) {
  write_slot(kCheckpointSlots[2], step, state);
}

void Recorder::drop_stop_checkpoint() {
  Impl& d = *impl_;
  try {
    if (!d.file.nameExists("/checkpoint") || !d.file.nameExists(kCheckpointSlots[2])) return;
    if (H5Ldelete(d.file.getId(), kCheckpointSlots[2], H5P_DEFAULT) < 0)
      throw H5::FileIException("H5Ldelete", kCheckpointSlots[2]);
    // A run stopped before its first regular checkpoint: the group goes too, as a run never
    // stopped has none.
    if (d.file.openGroup("/checkpoint").getNumObjs() == 0 && H5Ldelete(d.file.getId(), "/checkpoint", H5P_DEFAULT) < 0)
      throw H5::FileIException("H5Ldelete", "/checkpoint");
    flush_with_room(d.file);
  } catch (const H5::Exception& e) {
    d.write_failed = true;
    throw OutputError(partial_path_ + ": could not drop the stopped run's checkpoint (" + e.getDetailMsg() + ")");
  }
}

void Recorder::write_slot(const char* name, std::int64_t step, const std::vector<std::uint8_t>& state) {
  Impl& d = *impl_;
  try {
    d.write_buffers();
    H5::Group group = d.file.nameExists("/checkpoint") ? d.file.openGroup("/checkpoint") : d.file.createGroup("/checkpoint");
    const hsize_t size = state.size();
    if (!d.file.nameExists(name)) {
      const hsize_t zero = 0, unlimited = H5S_UNLIMITED, chunk = 1 << 16;
      H5::DataSpace space(1, &zero, &unlimited);
      H5::DSetCreatPropList plist;
      plist.setChunk(1, &chunk);
      H5Pset_obj_track_times(plist.getId(), false);
      d.file.createDataSet(name, H5::PredType::NATIVE_UINT8, space, plist);
    }
    H5::DataSet slot = d.file.openDataSet(name);
    if (H5Dset_extent(slot.getId(), &size) < 0) throw H5::DataSetIException("set_extent", name);
    if (size > 0) slot.write(state.data(), H5::PredType::NATIVE_UINT8);
    write_number_attribute(slot, "step", H5::PredType::NATIVE_INT64, step);
    write_number_attribute(slot, "checksum", H5::PredType::NATIVE_UINT64, slot_checksum(step, state));
    flush_with_room(d.file);
  } catch (const H5::Exception& e) {
    d.write_failed = true;
    throw OutputError(partial_path_ + ": could not write a checkpoint (" + e.getDetailMsg() + "); disk full? floedem run --resume continues it once there is room");
  }
}

RecordedRows Recorder::rows() const {
  const Impl& d = *impl_;
  return {frames(), contact_rows(), collision_rows(), static_cast<std::int64_t>(d.tow_time.rows() + d.w_time.size()),
          static_cast<std::int64_t>(d.load_time.rows() + d.l_time.size())};
}

std::int64_t Recorder::frame_chunk() const { return static_cast<std::int64_t>(impl_->frame_chunk); }

std::int64_t Recorder::check_tables(const std::string& file, const Scene& scene, const RecordedRows& rows) const {
  H5::Exception::dontPrint();
  try {
    H5::H5File f(file, H5F_ACC_RDONLY);
    const CheckedFile checked(f, file);
    const std::int64_t format = checked.check_format_version();
    Impl layout;
    layout.bodies = scene.bodies.size();
    layout.frame_chunk = frame_chunk_of(layout.bodies);
    layout.contact_output = scene.output.contacts;
    layout.set_tow(scene.tow);
    for (const Impl::Table& t : layout.tables(scene)) {
      std::vector<std::int64_t> shape{-1};
      for (const hsize_t d : t.row_shape) shape.push_back(static_cast<std::int64_t>(d));
      std::vector<hsize_t> dims;
      checked.dataset(t.path, t.type.getClass(), shape, dims);
      if (static_cast<std::int64_t>(dims[0]) < rows.*t.rows)
        checked.fail(t.path, "has " + std::to_string(dims[0]) + " rows; its checkpoint counts " +
                                 std::to_string(rows.*t.rows) + ": damaged");
    }
    return format;
  } catch (const H5::Exception& e) {
    throw InputError(file + ": cannot read it (" + e.getDetailMsg() + "); damaged, or not a floedem file?");
  }
}

void Recorder::check_space(const Scene& scene) const {
  // The frames' size is known before the run: 6 doubles per body and frame (position, angle,
  // velocity, angular velocity; 8 with a geographic scene's longitude and latitude), plus /tow's 9 per row (12 with a tug) and /loads' 1 + 2 per body per row. A
  // disk too small for them is told now, not hours into the run (contact rows depend on the run
  // and are not counted).
  const double steps = static_cast<double>(scene.run.steps());
  const double frames = steps / scene.run.output_every + 2.0;
  const double tow_rows = scene.tow.mode == TowSpec::Mode::none ? 0.0 : steps / scene.tow_every() + 2.0;
  const double load_rows = scene.output.load_bodies.empty() ? 0.0 : steps / scene.load_every() + 2.0;
  const double bytes =
      8.0 * (frames * ((scene.geo.present ? 8.0 : 6.0) * static_cast<double>(scene.bodies.size()) + 1.0) + 12.0 * tow_rows +
             load_rows * (1.0 + 2.0 * static_cast<double>(scene.output.load_bodies.size())));
  // A file-size limit on the process (`ulimit -f`, which Slurm passes on from the submitting
  // shell) is a disk as small as the limit.
  struct rlimit limit {};
  if (getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
      bytes > static_cast<double>(limit.rlim_cur)) {
    char text[256];
    std::snprintf(text, sizeof text, ": the frames alone need about %.3g MB and the file-size limit (ulimit -f) is %.3g MB",
                  bytes / 1e6, static_cast<double>(limit.rlim_cur) / 1e6);
    throw OutputError(path_ + text + " (fewer frames: a larger run.output_every)");
  }
  const std::filesystem::path dir = std::filesystem::absolute(path_).parent_path();
  struct statvfs fs {};
  if (statvfs(dir.c_str(), &fs) != 0) return;  // a missing directory is reported on creation
  const double free_bytes = static_cast<double>(fs.f_bavail) * static_cast<double>(fs.f_frsize);
  if (bytes > free_bytes) {
    char text[256];
    std::snprintf(text, sizeof text, ": the frames alone need about %.3g MB and %.3g MB are free there", bytes / 1e6,
                  free_bytes / 1e6);
    throw OutputError(path_ + text + " (fewer frames: a larger run.output_every)");
  }
}

Recorder::~Recorder() {
  // A run that did not finish: keep what was recorded, readable, under the .partial name
  // (not after a failed write: the file cannot be made consistent then, and HDF5 would only
  // fail again).
  if (impl_ && !impl_->closed && !impl_->write_failed) {
    try {
      impl_->flush();
      impl_->file.close();
    } catch (...) {
    }
  }
  // After a failed write the file's datasets cannot be closed either, and the HDF5 C++ API's
  // destructors say so on stderr, a line a dataset, after which the one-line
  // error would come last. Their handles are left to the end of the process instead (the
  // command exits at once, without exit handlers: app/main.cpp).
  if (impl_ && impl_->write_failed) static_cast<void>(impl_.release());
}

void Recorder::write_frame(double time, const BodyStates& state) {
  Impl& d = *impl_;
  d.b_time.push_back(time);
  for (std::size_t i = 0; i < d.bodies; ++i) {
    d.b_position.push_back(state.position[i].x);
    d.b_position.push_back(state.position[i].y);
    d.b_angle.push_back(state.angle[i]);
    d.b_velocity.push_back(state.velocity[i].x);
    d.b_velocity.push_back(state.velocity[i].y);
    d.b_angular_velocity.push_back(state.angular_velocity[i]);
  }
  if (d.geo)
    for (std::size_t i = 0; i < d.bodies; ++i) {
      const LonLat g = d.geo->to_lonlat(state.position[i]);  // NaN beyond the projection's domain
      d.b_lonlat.push_back(g.lon);
      d.b_lonlat.push_back(g.lat);
    }
  ++d.buffered_frames;
  try {
    if (d.buffered_frames >= d.frame_chunk) d.flush();
  } catch (const H5::Exception& e) {
    impl_->write_failed = true;
    throw OutputError(partial_path_ + ": write failed (" + e.getDetailMsg() + "); disk full? floedem run --resume continues it once there is room");
  }
}

void Recorder::write_contacts(double time, std::span<const ContactRecord> contacts) {
  Impl& d = *impl_;
  if (d.contact_output == ContactOutput::none) return;
  for (const ContactRecord& c : contacts) {
    if (d.contact_output == ContactOutput::collisions && c.kind != ContactKind::collision) continue;
    d.k_time.push_back(time);
    d.k_body_a.push_back(c.body_a);
    d.k_body_b.push_back(c.body_b);
    d.k_point.push_back(c.point.x);
    d.k_point.push_back(c.point.y);
    d.k_normal.push_back(c.normal.x);
    d.k_normal.push_back(c.normal.y);
    d.k_normal_impulse.push_back(c.normal_impulse);
    d.k_tangent_impulse.push_back(c.tangent_impulse);
    d.k_approach.push_back(c.approach_velocity);
    d.k_separation.push_back(c.separation);
    d.k_kind.push_back(static_cast<std::uint8_t>(c.kind));
  }
  try {
    if (d.k_time.size() >= 4096) d.flush();
  } catch (const H5::Exception& e) {
    impl_->write_failed = true;
    throw OutputError(partial_path_ + ": write failed (" + e.getDetailMsg() + "); disk full? floedem run --resume continues it once there is room");
  }
}

void Recorder::write_collisions(std::span<const CollisionRow> rows) {
  Impl& d = *impl_;
  d.events.insert(d.events.end(), rows.begin(), rows.end());
  try {
    if (d.events.size() >= 1024) d.flush();
  } catch (const H5::Exception& e) {
    impl_->write_failed = true;
    throw OutputError(partial_path_ + ": could not write collisions (" + e.getDetailMsg() + "); disk full? floedem run --resume continues it once there is room");
  }
}

std::int64_t Recorder::collision_rows() const {
  return static_cast<std::int64_t>(impl_->e_time.rows() + impl_->events.size());
}

void Recorder::write_loads(double time, std::span<const Vec2> forces) {
  Impl& d = *impl_;
  d.l_time.push_back(time);
  for (const Vec2 f : forces) d.l_force.insert(d.l_force.end(), {f.x, f.y});
  if (d.l_time.size() >= 4096) d.flush();
}

void Recorder::write_tow(double time, const TowFrame& f) {
  Impl& d = *impl_;
  d.w_time.push_back(time);
  d.w_force.insert(d.w_force.end(), {f.force.x, f.force.y});
  d.w_mean.insert(d.w_mean.end(), {f.force_mean.x, f.force_mean.y});
  d.w_ice.insert(d.w_ice.end(), {f.ice_force_mean.x, f.ice_force_mean.y});
  d.w_tug.insert(d.w_tug.end(), {f.tug_position.x, f.tug_position.y});
  if (d.rope) d.w_tension.push_back(f.tension_max);
  if (d.tug) d.w_tug_velocity.insert(d.w_tug_velocity.end(), {f.tug_velocity.x, f.tug_velocity.y});
  if (d.w_time.size() >= 4096) d.flush();
}

std::int64_t Recorder::frames() const {
  return static_cast<std::int64_t>(impl_->time.rows() + impl_->buffered_frames);
}
std::int64_t Recorder::contact_rows() const {
  return static_cast<std::int64_t>(impl_->c_time.rows() + impl_->k_time.size());
}

void Recorder::update_engine_info(const EngineInfo& engine) {
  try {
    H5::Group eng = impl_->file.openGroup("/engine");
    for (const auto& [k, v] : engine.settings) write_text(eng, k, v, impl_->fixed_strings);
  } catch (const H5::Exception& e) {
    throw OutputError(partial_path_ + ": could not update /engine (" + e.getDetailMsg() + ")");
  }
}

namespace {
H5::Group open_or_create(H5::H5File& file, const std::string& group) {
  return file.nameExists(group) ? file.openGroup(group) : file.createGroup(group);
}
}  // namespace

void Recorder::write_polygons(const std::string& group, const std::string& name,
                              const std::vector<std::vector<Vec2>>& polygons) {
  std::vector<double> vertices;
  std::vector<std::int64_t> offsets{0};
  for (const auto& p : polygons) {
    for (const Vec2 v : p) {
      vertices.push_back(v.x);
      vertices.push_back(v.y);
    }
    offsets.push_back(static_cast<std::int64_t>(vertices.size() / 2));
  }
  try {
    H5::Group g = open_or_create(impl_->file, group);
    write_fixed(g, name + "_vertices", H5::PredType::NATIVE_DOUBLE, vertices, {vertices.size() / 2, 2});
    write_fixed(g, name + "_offsets", H5::PredType::NATIVE_INT64, offsets, {offsets.size()});
  } catch (const H5::Exception& e) {
    throw OutputError(partial_path_ + ": could not write " + group + "/" + name + " (" + e.getDetailMsg() + ")");
  }
}

void Recorder::discard() {
  if (impl_ && !impl_->closed) {
    try {
      impl_->file.close();
    } catch (...) {
    }
    impl_->closed = true;
  }
  std::error_code ec;
  std::filesystem::remove(partial_path_, ec);
}

void Recorder::finish(const std::vector<std::pair<std::string, double>>& summary) {
  Impl& d = *impl_;
  drop_stop_checkpoint();  // a run stopped and continued past its last regular checkpoint holds one
  try {
    H5::Group root = d.file.openGroup("/");
    for (const auto& [k, v] : summary) write_attribute(root, "summary_" + k, v);
    write_text(root, "status", "complete", impl_->fixed_strings);
    d.flush();
    d.file.close();
    d.closed = true;
  } catch (const H5::Exception& e) {
    impl_->write_failed = true;
    throw OutputError(partial_path_ + ": could not complete the file (" + e.getDetailMsg() + "); disk full? floedem run --resume continues it once there is room");
  }
  if (std::rename(partial_path_.c_str(), path_.c_str()) != 0)
    throw OutputError(partial_path_ + ": cannot rename to " + path_ + ": " + std::strerror(errno));
}

}  // namespace floedem
