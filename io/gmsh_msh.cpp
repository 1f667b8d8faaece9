// Gmsh MSH 2.2 / 4.1 reader (ASCII and binary).
// Format reference: the "MSH file format" chapter of the Gmsh manual.
#include "io/gmsh_reader.hpp"

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>
#include <utility>

#include "base/errors.hpp"
#include "io/gmsh_buffer.hpp"

namespace fdem::io {
namespace {

constexpr int kLine2 = 1;
constexpr int kTri3 = 2;
constexpr int kPoint = 15;

struct ElementKind {
  int type;
  int nodes;
  int dim;
  const char* name;
};

// Node counts are needed to step over element types we do not keep (binary files have
// no line ends to skip to).
constexpr ElementKind kElementKinds[] = {
    {1, 2, 1, "2-node line"}, {2, 3, 2, "3-node triangle"}, {3, 4, 2, "4-node quadrangle"},
    {4, 4, 3, "4-node tetrahedron"}, {5, 8, 3, "8-node hexahedron"}, {6, 6, 3, "6-node prism"},
    {7, 5, 3, "5-node pyramid"}, {8, 3, 1, "3-node line"}, {9, 6, 2, "6-node triangle"},
    {10, 9, 2, "9-node quadrangle"}, {11, 10, 3, "10-node tetrahedron"}, {12, 27, 3, "27-node hexahedron"},
    {13, 18, 3, "18-node prism"}, {14, 14, 3, "14-node pyramid"}, {15, 1, 0, "point"},
    {16, 8, 2, "8-node quadrangle"}, {17, 20, 3, "20-node hexahedron"}, {18, 15, 3, "15-node prism"},
    {19, 13, 3, "13-node pyramid"}, {20, 9, 2, "9-node triangle"}, {21, 10, 2, "10-node triangle"},
    {22, 12, 2, "12-node triangle"}, {23, 15, 2, "15-node triangle"}, {24, 15, 2, "15-node triangle"},
    {25, 21, 2, "21-node triangle"}, {26, 4, 1, "4-node line"}, {27, 5, 1, "5-node line"},
    {28, 6, 1, "6-node line"}, {29, 20, 3, "20-node tetrahedron"}, {30, 35, 3, "35-node tetrahedron"},
    {31, 56, 3, "56-node tetrahedron"},
};

const ElementKind* find_kind(int type) {
  for (const auto& k : kElementKinds)
    if (k.type == type) return &k;
  return nullptr;
}

const char* entity_word(int dim) {
  static const char* const words[] = {"point", "curve", "surface", "volume"};
  return dim >= 0 && dim <= 3 ? words[dim] : "entity";
}

struct ElementRef {
  size_t pos;  // where in the file, for messages
  int entity_tag;
};

class MshReader {
 public:
  MshReader(MshBuffer& in, std::vector<std::string>* notes) : in_(in), notes_(notes) {}

  Mesh read() {
    mesh_.source = in_.path();
    read_format();
    bool have_nodes = false, have_elements = false;
    while (!in_.at_end()) {
      size_t at = in_.mark();
      std::string header = in_.next_line();
      if (header.size() < 2 || header[0] != '$' || header.compare(0, 4, "$End") == 0)
        in_.fail_at(at, "expected a section header such as $Nodes, found '" + header.substr(0, 40) + "'");
      std::string name = header.substr(1);
      in_.section = name;
      if (name == "PhysicalNames") {
        read_physical_names();
      } else if (name == "Entities" && version_ == 4) {
        read_entities();
      } else if (name == "Nodes") {
        if (have_nodes) in_.fail_at(at, "second $Nodes section");
        version_ == 2 ? read_nodes_v2() : read_nodes_v4();
        have_nodes = true;
      } else if (name == "Elements") {
        if (!have_nodes) in_.fail_at(at, "$Elements before $Nodes");
        if (have_elements) in_.fail_at(at, "second $Elements section");
        version_ == 2 ? read_elements_v2() : read_elements_v4();
        have_elements = true;
      } else {
        in_.skip_section(name);  // $Periodic, $NodeData, $PartitionedEntities, ...
      }
    }
    if (!have_nodes) throw InputError(in_.path() + ": no $Nodes section");
    if (!have_elements) throw InputError(in_.path() + ": no $Elements section");
    finish();
    return std::move(mesh_);
  }

 private:
  void note(const std::string& s) {
    if (notes_) notes_->push_back(s);
  }

  void read_format() {
    in_.skip_space();
    in_.section = "MeshFormat";
    std::string first = in_.next_line();
    if (first != "$MeshFormat")
      throw InputError(in_.path() + ": not a Gmsh .msh file (it does not start with $MeshFormat)");
    std::string version = in_.token("format version");
    if (version == "2.2")
      version_ = 2;
    else if (version == "4.1")
      version_ = 4;
    else
      in_.fail("unsupported MSH version " + version + "; fdem reads MSH 2.2 and 4.1 (ASCII or binary): re-export with gmsh -format msh41");
    long long file_type = in_.ascii_int("file type");
    long long data_size = in_.ascii_int("data size");
    if (file_type != 0 && file_type != 1) in_.fail("file type must be 0 (ASCII) or 1 (binary), found " + std::to_string(file_type));
    if (version_ == 4 && data_size != 4 && data_size != 8) in_.fail("data size must be 4 or 8, found " + std::to_string(data_size));
    if (version_ == 2 && data_size != 8) in_.fail("data size must be 8, found " + std::to_string(data_size));
    in_.size_t_bytes = static_cast<int>(data_size);
    if (file_type == 1) {
      in_.end_ascii_line();
      in_.binary = true;
      // 1 read as 0x01000000: written on a machine of the other byte order, so every
      // binary value is to be swapped.
      const int32_t one = in_.raw<int32_t>("endianness check");
      if (one != 1 && one != 0x01000000)
        in_.fail_at(in_.pos() - 4, "binary endianness check failed (expected the integer 1 after the format line)");
      in_.swap_bytes = one != 1;
    }
    in_.expect_end("MeshFormat");
  }

  void read_physical_names() {
    // ASCII in binary files too.
    bool binary = in_.binary;
    in_.binary = false;
    long long n = in_.get_count(in_.ascii_int("number of physical names"), "number of physical names");
    for (long long i = 0; i < n; ++i) {
      int dim = static_cast<int>(in_.ascii_int("physical dimension"));
      int tag = static_cast<int>(in_.ascii_int("physical tag"));
      if (dim < 0 || dim > 3) in_.fail("physical dimension must be 0..3, found " + std::to_string(dim));
      names_[{dim, tag}] = in_.quoted("physical name");
    }
    in_.expect_end("PhysicalNames");
    in_.binary = binary;
  }

  void read_entities() {
    long long count[4];
    for (auto& c : count) c = in_.get_count(in_.get_size("number of entities"), "number of entities");
    for (int dim = 0; dim < 4; ++dim) {
      for (long long i = 0; i < count[dim]; ++i) {
        int tag = static_cast<int>(in_.get_int("entity tag"));
        for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) in_.get_real("bounding box coordinate");
        long long nphys = in_.get_count(in_.get_size("number of physical tags"), "number of physical tags");
        std::vector<int>& phys = entity_physicals_[{dim, tag}];
        for (long long p = 0; p < nphys; ++p) phys.push_back(static_cast<int>(in_.get_int("physical tag")));
        if (dim > 0) {
          long long nb = in_.get_count(in_.get_size("number of bounding entities"), "number of bounding entities");
          for (long long b = 0; b < nb; ++b) in_.get_int("bounding entity tag");
        }
      }
    }
    in_.expect_end("Entities");
  }

  void add_node(long long tag, double x, double y, size_t at) {
    if (!node_index_.emplace(tag, static_cast<int>(mesh_.x.size())).second)
      in_.fail_at(at, "node tag " + std::to_string(tag) + " appears twice");
    mesh_.node_tags.push_back(static_cast<long>(tag));
    mesh_.x.push_back(x);
    mesh_.y.push_back(y);
  }

  void read_nodes_v2() {
    long long n = in_.get_count(in_.ascii_int("number of nodes"), "number of nodes");
    if (in_.binary) in_.end_ascii_line();
    for (long long i = 0; i < n; ++i) {
      size_t at = in_.mark();
      long long tag = in_.get_int("node tag");
      double x = in_.get_real("x coordinate");
      double y = in_.get_real("y coordinate");
      in_.get_real("z coordinate");
      add_node(tag, x, y, at);
    }
    in_.expect_end("Nodes");
  }

  void read_nodes_v4() {
    long long blocks = in_.get_count(in_.get_size("number of node blocks"), "number of node blocks");
    for (int k = 0; k < 3; ++k) in_.get_size("node count or tag range");
    std::vector<std::pair<long long, size_t>> tags;
    for (long long b = 0; b < blocks; ++b) {
      int dim = static_cast<int>(in_.get_int("entity dimension"));
      in_.get_int("entity tag");
      long long parametric = in_.get_int("parametric flag");
      long long n = in_.get_count(in_.get_size("number of nodes in block"), "number of nodes in block");
      tags.clear();
      for (long long i = 0; i < n; ++i) {
        size_t at = in_.mark();
        tags.emplace_back(in_.get_size("node tag"), at);
      }
      int extra = parametric ? std::clamp(dim, 0, 3) : 0;  // u, v, w parametric coordinates
      for (const auto& [tag, at] : tags) {
        double x = in_.get_real("x coordinate");
        double y = in_.get_real("y coordinate");
        in_.get_real("z coordinate");
        for (int e = 0; e < extra; ++e) in_.get_real("parametric coordinate");
        add_node(tag, x, y, at);
      }
    }
    in_.expect_end("Nodes");
  }

  // Keeps or counts one element. `node_tags` holds the element's node tags.
  void add_element(int type, long long tag, int physical, const ElementRef& ref, const std::vector<long long>& node_tags) {
    mesh_.max_element_tag = std::max(mesh_.max_element_tag, static_cast<long>(tag));
    if (type != kTri3 && type != kLine2 && type != kPoint) {
      ++skipped_[type];
      return;
    }
    int idx[3] = {0, 0, 0};
    for (size_t i = 0; i < node_tags.size(); ++i) {
      auto it = node_index_.find(node_tags[i]);
      if (it == node_index_.end())
        in_.fail_at(ref.pos, "element " + std::to_string(tag) + " refers to unknown node tag " + std::to_string(node_tags[i]));
      idx[i] = it->second;
    }
    if (type == kTri3) {
      if (physical == 0 && !untagged_triangle_) untagged_triangle_ = ref;
      mesh_.triangles.push_back({idx[0], idx[1], idx[2]});
      mesh_.triangle_group.push_back(physical);  // physical tag until finish() maps it
      mesh_.triangle_tags.push_back(static_cast<long>(tag));
      triangle_entity_.push_back(ref.entity_tag);
    } else if (physical == 0) {
      ++dropped_[type];  // a curve or point outside every physical group cannot carry a boundary condition
    } else if (type == kLine2) {
      mesh_.lines.push_back({idx[0], idx[1]});
      mesh_.line_group.push_back(physical);
      mesh_.line_tags.push_back(static_cast<long>(tag));
      line_entity_.push_back(ref.entity_tag);
    } else {
      mesh_.points.push_back(idx[0]);
      mesh_.point_group.push_back(physical);
      point_entity_.push_back(ref.entity_tag);
    }
    if (physical != 0) used_.insert({find_kind(type)->dim, physical});
    if (physical != 0 && version_ == 2) {
      // MSH 2.2 has no $Entities: learn each entity's physical groups from its elements.
      std::vector<int>& phys = entity_physicals_[{find_kind(type)->dim, ref.entity_tag}];
      if (std::find(phys.begin(), phys.end(), physical) == phys.end()) phys.push_back(physical);
    }
  }

  // nullptr for a type we do not know; ASCII readers then step over the rest of the line.
  const ElementKind* element_kind(int type, size_t at) {
    const ElementKind* kind = find_kind(type);
    if (!kind && in_.binary) in_.fail_at(at, "unknown Gmsh element type " + std::to_string(type) + " (cannot step over it in a binary file)");
    return kind;
  }

  void read_elements_v2() {
    long long n = in_.get_count(in_.ascii_int("number of elements"), "number of elements");
    if (in_.binary) in_.end_ascii_line();
    std::vector<long long> nodes;
    long long done = 0;
    while (done < n) {
      // ASCII: one element per line. Binary: a header (type, count, number of tags)
      // followed by `count` elements of that type.
      long long tag = 0, type, follow = 1, ntags;
      size_t at = in_.mark();
      if (in_.binary) {
        type = in_.get_int("element type");
        follow = in_.get_count(in_.get_int("number of elements following"), "number of elements following");
        ntags = in_.get_int("number of element tags");
        if (follow < 1 || follow > n - done) in_.fail_at(at, "element block size " + std::to_string(follow) + " does not fit the element count");
      } else {
        tag = in_.ascii_int("element tag");
        type = in_.ascii_int("element type");
        ntags = in_.ascii_int("number of element tags");
      }
      if (ntags < 0 || ntags > 64) in_.fail_at(at, "implausible number of element tags " + std::to_string(ntags));
      const ElementKind* kind = element_kind(static_cast<int>(type), at);
      for (long long e = 0; e < follow; ++e) {
        at = in_.mark();
        if (in_.binary) tag = in_.get_int("element tag");
        long long physical = 0, entity = 0;
        for (long long t = 0; t < ntags; ++t) {
          long long v = in_.get_int("element tag list entry");
          if (t == 0) physical = v;  // 2.2 convention: physical group, then elementary entity
          if (t == 1) entity = v;
        }
        if (!kind) {
          ++skipped_[static_cast<int>(type)];
          in_.rest_of_line();
          continue;
        }
        nodes.clear();
        for (int k = 0; k < kind->nodes; ++k) nodes.push_back(in_.get_int("node tag"));
        add_element(static_cast<int>(type), tag, static_cast<int>(physical), {at, static_cast<int>(entity)}, nodes);
      }
      done += follow;
    }
    in_.expect_end("Elements");
  }

  // Physical tag of a 4.1 entity: the first of its $Entities physical tags, 0 if none.
  int physical_of_entity(int dim, int tag) {
    auto it = entity_physicals_.find({dim, tag});
    if (it == entity_physicals_.end() || it->second.empty()) return 0;
    const std::vector<int>& phys = it->second;
    if (phys.size() > 1 && multi_noted_.insert({dim, tag}).second) {
      std::string list;
      for (int p : phys) list += (list.empty() ? "" : ", ") + std::to_string(p);
      note(in_.path() + ": " + entity_word(dim) + " entity " + std::to_string(tag) + " is in physical groups " + list +
           "; its elements are assigned to the first (" + std::to_string(phys[0]) + ") only");
    }
    return phys[0];
  }

  void read_elements_v4() {
    long long blocks = in_.get_count(in_.get_size("number of element blocks"), "number of element blocks");
    for (int k = 0; k < 3; ++k) in_.get_size("element count or tag range");
    std::vector<long long> nodes;
    for (long long b = 0; b < blocks; ++b) {
      size_t at = in_.mark();
      int dim = static_cast<int>(in_.get_int("entity dimension"));
      int entity = static_cast<int>(in_.get_int("entity tag"));
      int type = static_cast<int>(in_.get_int("element type"));
      long long n = in_.get_count(in_.get_size("number of elements in block"), "number of elements in block");
      const ElementKind* kind = element_kind(type, at);
      int physical = physical_of_entity(dim, entity);
      for (long long e = 0; e < n; ++e) {
        at = in_.mark();
        long long tag = in_.get_size("element tag");
        if (!kind) {
          ++skipped_[type];
          in_.rest_of_line();
          continue;
        }
        nodes.clear();
        for (int k = 0; k < kind->nodes; ++k) nodes.push_back(in_.get_size("node tag"));
        add_element(type, tag, physical, {at, entity}, nodes);
      }
    }
    in_.expect_end("Elements");
  }

  // MSH 2.2 writes an element once per physical group of its entity, under new element
  // tags. Keeps the first copy, as 4.1 files keep the first physical tag of the entity.
  template <size_t N>
  void drop_duplicates(int dim, std::vector<std::array<int, N>>& elements, std::vector<int>& group,
                       std::vector<int>& entity, std::vector<long>* tags) {
    std::set<std::pair<int, std::array<int, N>>> seen;
    size_t kept = 0;
    for (size_t i = 0; i < elements.size(); ++i) {
      auto phys = entity_physicals_.find({dim, entity[i]});
      if (phys != entity_physicals_.end() && phys->second.size() > 1) {
        physical_of_entity(dim, entity[i]);  // notes the entity once
        std::array<int, N> sorted = elements[i];
        std::sort(sorted.begin(), sorted.end());
        if (!seen.insert({entity[i], sorted}).second) continue;
      }
      elements[kept] = elements[i];
      group[kept] = group[i];
      entity[kept] = entity[i];
      if (tags) (*tags)[kept] = (*tags)[i];
      ++kept;
    }
    elements.resize(kept);
    group.resize(kept);
    entity.resize(kept);
    if (tags) tags->resize(kept);
  }

  void finish() {
    if (version_ == 2) {
      drop_duplicates(2, mesh_.triangles, mesh_.triangle_group, triangle_entity_, &mesh_.triangle_tags);
      drop_duplicates(1, mesh_.lines, mesh_.line_group, line_entity_, &mesh_.line_tags);
      std::vector<std::array<int, 1>> points(mesh_.points.size());
      for (size_t i = 0; i < points.size(); ++i) points[i] = {mesh_.points[i]};
      drop_duplicates(0, points, mesh_.point_group, point_entity_, nullptr);
      mesh_.points.resize(points.size());
      for (size_t i = 0; i < points.size(); ++i) mesh_.points[i] = points[i][0];
    }
    bool any_groups = !names_.empty() || !used_.empty();
    for (const auto& [key, phys] : entity_physicals_) any_groups = any_groups || !phys.empty();

    bool skipped_2d = false;
    for (const auto& [type, count] : skipped_) {
      const ElementKind* kind = find_kind(type);
      std::string what = kind ? std::string(kind->name) : "unknown element type";
      if (kind && kind->dim == 2) skipped_2d = true;
      std::string why = kind && kind->dim == 2 && std::string(kind->name).find("triangle") != std::string::npos
                            ? ": fdem uses 3-node triangles only; mesh with Mesh.ElementOrder = 1"
                            : ": fdem keeps only 3-node triangles, 2-node lines and points";
      note(in_.path() + ": skipped " + std::to_string(count) + " elements of Gmsh type " + std::to_string(type) + " (" + what + ")" + why);
    }
    for (const auto& [type, count] : dropped_)
      note(in_.path() + ": ignored " + std::to_string(count) + " " + find_kind(type)->name + " elements outside any physical group");

    if (mesh_.triangles.empty()) {
      if (skipped_2d)
        throw InputError(in_.path() + ": no 3-node triangles (Gmsh type 2) to simulate, only other 2D elements (see the skipped types): fdem uses 3-node triangles only; mesh with Mesh.ElementOrder = 1 and without recombination");
      throw InputError(in_.path() + ": no 3-node triangles (Gmsh type 2): nothing to simulate; is the .geo meshed in 2D with Plane Surfaces?");
    }
    if (!any_groups)
      throw InputError(in_.path() + ": the mesh has no physical groups; fdem needs named physical surfaces to assign materials: add Physical Surface(\"rock\") = {...} to the .geo");
    if (untagged_triangle_) {
      const ElementRef& ref = *untagged_triangle_;
      in_.section.clear();
      in_.fail_at(ref.pos, "triangles of surface entity " + std::to_string(ref.entity_tag) +
                               " have no physical group; name every surface in the .geo (Physical Surface(\"rock\") = {...})" +
                               (version_ == 2 ? " (MSH 2.2 files saved with Mesh.SaveAll = 1 carry no physical tags at all)" : ""));
    }

    // Groups sorted by (dim, tag) so that all file forms of one mesh list them alike.
    std::set<std::pair<int, int>> keys = used_;
    for (const auto& [key, name] : names_) keys.insert(key);
    std::map<std::pair<int, int>, int> index;
    for (const auto& key : keys) {
      index[key] = static_cast<int>(mesh_.groups.size());
      auto name = names_.find(key);
      mesh_.groups.push_back({key.first, key.second, name == names_.end() ? std::string() : name->second});
    }
    mesh_.triangle_entity = triangle_entity_;
    for (int& g : mesh_.triangle_group) g = index.at({2, g});
    for (int& g : mesh_.line_group) g = index.at({1, g});
    for (int& g : mesh_.point_group) g = index.at({0, g});
  }

  MshBuffer& in_;
  std::vector<std::string>* notes_;
  Mesh mesh_;
  int version_ = 0;
  std::unordered_map<long long, int> node_index_;
  std::map<std::pair<int, int>, std::string> names_;                 // (dim, physical tag) -> name
  std::map<std::pair<int, int>, std::vector<int>> entity_physicals_;  // (dim, entity tag) -> physical tags
  std::set<std::pair<int, int>> used_;                                // (dim, physical tag) of kept elements
  std::set<std::pair<int, int>> multi_noted_;
  std::map<int, long long> skipped_;  // element type -> count
  std::map<int, long long> dropped_;  // kept type without physical group -> count
  std::optional<ElementRef> untagged_triangle_;
  std::vector<int> triangle_entity_, line_entity_, point_entity_;  // elementary entity tag per kept element
};

}  // namespace

Mesh read_gmsh(const std::string& path, std::vector<std::string>* notes) {
  MshBuffer buffer(path, read_file_bytes(path, "Gmsh mesh file"));
  return MshReader(buffer, notes).read();
}

}  // namespace fdem::io
