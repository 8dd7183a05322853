// A glTF's skins following a deformation (gltf_rig.h).
#include "gltf_rig.h"

#include <algorithm>
#include <map>
#include <set>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "gltf_scene.h"
#include "linalg/nearest_rotation.h"

namespace specdeform::detail {

namespace {

// "1 joint", "4 joints".
std::string counted(size_t n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

// A rigid motion x -> R x + t.
struct Rigid {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();

  bool operator==(const Rigid& o) const { return R == o.R && t == o.t; }
  Eigen::Matrix4d matrix() const {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = R;
    m.topRightCorner<3, 1>() = t;
    return m;
  }
  // this^-1 * o
  Rigid relative(const Rigid& o) const { return {R.transpose() * o.R, R.transpose() * (o.t - t)}; }
};

// Weighted sums of the vertices a joint drives.
struct Fit {
  double weight = 0.0;
  Eigen::Vector3d rest = Eigen::Vector3d::Zero(), moved = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  bool any_moved = false;
};

Eigen::Matrix4d column_major(const AccessorValues& v, int i) {
  Eigen::Matrix4d m;
  for (int k = 0; k < 16; ++k) m(k % 4, k / 4) = v(i, k);
  return m;
}

// Each skinned drawing's (JOINTS_k, WEIGHTS_k) accessor pairs and its skin.
struct Influences {
  int skin = -1;
  std::vector<std::pair<int, int>> sets;
};

Influences influences(const Json& json, const GltfUnit& unit) {
  Influences out;
  const Json& node = json["nodes"][unit.node];
  if (!node.contains("skin")) return out;
  out.skin = json_index(node["skin"]);
  const Json& attributes =
      object_at(json["meshes"][unit.mesh]["primitives"][unit.primitive], "attributes");
  for (int k = 0;; ++k) {
    const std::string j = "JOINTS_" + std::to_string(k), w = "WEIGHTS_" + std::to_string(k);
    if (!attributes.contains(j) || !attributes.contains(w)) break;
    out.sets.emplace_back(json_index(attributes[j]), json_index(attributes[w]));
  }
  return out;
}

class Follower {
 public:
  Follower(GltfDocument& doc, const GltfLayout& layout)
      : doc_(doc), original_(layout.doc), in_(layout.doc.json) {
    const Json& nodes = array_at(in_, "nodes");
    parent_.assign(nodes.size(), -1);
    for (size_t n = 0; n < nodes.size(); ++n)
      for (const Json& c : array_at(nodes[n], "children"))
        if (const int child = json_index(c); child >= 0 && size_t(child) < nodes.size()) {
          parent_[child] = int(n);
        }
    // Children lists that loop (outside the scene, which the reader checks) are cut where they
    // close, so that every walk up the parents ends.
    for (size_t n = 0; n < nodes.size(); ++n) {
      int up = int(n);
      for (size_t steps = 0; up >= 0 && steps <= nodes.size(); ++steps) up = parent_[up];
      if (up >= 0) parent_[n] = -1;
    }
    for (size_t s = 0; s < array_at(in_, "skins").size(); ++s) {
      const Json& skin = in_["skins"][s];
      const int ibm =
          skin.contains("inverseBindMatrices") ? json_index(skin["inverseBindMatrices"]) : -1;
      const AccessorValues m =
          ibm >= 0 ? read_accessor(layout.doc, ibm, "skin " + std::to_string(s) + " matrices")
                   : AccessorValues{};
      const Json& joints = array_at(skin, "joints");
      ibm_.push_back(m);
      const bool named = std::all_of(joints.begin(), joints.end(), [&](const Json& j) {
        return json_index(j) >= 0 && size_t(json_index(j)) < nodes.size();
      });
      if (!named || (ibm >= 0 && (m.components != 16 || m.count < int(joints.size())))) {
        skipped_.push_back(
            "skin " + std::to_string(s) + " (" +
            (named ? "fewer inverse bind matrices than joints" : "a joint that is not a node") +
            ")");
        continue;
      }
      valid_.insert(int(s));
      for (size_t j = 0; j < joints.size(); ++j) {
        const int node = json_index(joints[j]);
        if (!bind_.count(node)) {
          bind_[node] = ibm >= 0 ? Eigen::Matrix4d(column_major(m, int(j)).inverse())
                                 : Eigen::Matrix4d::Identity();
        }
      }
    }
  }

  bool any_skin() const { return !bind_.empty(); }

  // The weighted sums of each joint's vertices (two passes: centroids, then the covariance).
  void fit(const GltfLayout& layout, const Vertices& rest, const Vertices& positions) {
    std::vector<std::pair<size_t, Influences>> skinned;
    for (size_t u = 0; u < layout.units.size(); ++u) {
      Influences i = influences(in_, layout.units[u]);
      if (valid_.count(i.skin) && !i.sets.empty()) skinned.emplace_back(u, std::move(i));
    }
    for (const int pass : {0, 1}) {
      for (const auto& [u, inf] : skinned) {
        const GltfUnit& unit = layout.units[u];
        const Json& joints = in_["skins"][inf.skin]["joints"];
        for (const auto& [ja, wa] : inf.sets) {
          const AccessorValues J = read_accessor(layout.doc, ja, "JOINTS", true);
          const AccessorValues W = read_accessor(layout.doc, wa, "WEIGHTS");
          if (J.count != unit.count || W.count != unit.count || J.components != W.components) {
            if (pass == 0) {
              skipped_.push_back("mesh " + std::to_string(unit.mesh) + " primitive " +
                                 std::to_string(unit.primitive) +
                                 "'s weights (not one per vertex)");
            }
            continue;
          }
          for (int i = 0; i < unit.count; ++i) {
            const int v = unit.first_vertex + i;
            const Eigen::Vector3d x = rest.row(v), y = positions.row(v);
            for (int k = 0; k < J.components; ++k) {
              const double w = W(i, k);
              const size_t j = size_t(J(i, k));
              if (!(w > 0.0) || j >= joints.size()) continue;
              Fit& f = fits_[json_index(joints[j])];
              if (pass == 0) {
                f.weight += w;
                f.rest += w * x;
                f.moved += w * y;
                f.any_moved |= x != y;
              } else if (f.any_moved) {
                f.cov += w * (y - f.moved / f.weight) * (x - f.rest / f.weight).transpose();
              }
            }
          }
        }
      }
    }
  }

  // Each node's motion: a joint's own (fitted, else its nearest joint ancestor's), another node
  // its parent's (what carries it), in order from the roots.
  void motions() {
    const size_t n = parent_.size();
    carried_.assign(n, Rigid{});
    std::vector<char> done(n, 0);
    const auto visit = [&](auto&& self, int node) -> void {
      if (done[node]) return;
      if (parent_[node] >= 0) self(self, parent_[node]);
      done[node] = 1;
      const Rigid from_parent = parent_[node] >= 0 ? carried_[parent_[node]] : Rigid{};
      const auto f = fits_.find(node);
      if (!bind_.count(node) || f == fits_.end()) {
        carried_[node] = from_parent;
        return;
      }
      const Fit& fit = f->second;
      if (!fit.any_moved) return;  // the identity
      const Eigen::Vector3d c = fit.rest / fit.weight, c_moved = fit.moved / fit.weight;
      Rigid& T = carried_[node];
      // Vertices on a line (or one) leave the turn about it open: the parent's turn then.
      const Eigen::Vector3d s = Eigen::JacobiSVD<Eigen::Matrix3d>(fit.cov).singularValues();
      T.R = s[1] > 1e-9 * s[0] ? nearest_rotation(fit.cov) : from_parent.R;
      T.t = c_moved - T.R * c;
      ++followed_;
    };
    for (size_t node = 0; node < n; ++node) visit(visit, int(node));
  }

  // The bind-pose world matrix of every node: a joint's B, another node its parent's times its
  // own transform.
  Eigen::Matrix4d bind_world(int node) {
    if (const auto b = bind_.find(node); b != bind_.end()) return b->second;
    const Eigen::Matrix4d own = node_matrix(in_["nodes"][node]);
    return parent_[node] >= 0 ? Eigen::Matrix4d(bind_world(parent_[node]) * own) : own;
  }

  // K_j for every joint whose transforms change.
  void corrections() {
    for (const auto& [node, B] : bind_) {
      const Rigid parent = parent_[node] >= 0 ? carried_[parent_[node]] : Rigid{};
      if (carried_[node] == parent) continue;
      const Eigen::Matrix4d P =
          parent_[node] >= 0 ? bind_world(parent_[node]) : Eigen::Matrix4d::Identity();
      correct(node, P.inverse() * parent.relative(carried_[node]).matrix() * P,
              P.topRightCorner<3, 1>().norm() + carried_[node].t.norm(), "joint");
    }
  }

  // A mesh a joint carries (a hat, a sword: a node drawing a mesh without a skin, a joint's
  // child, no joint below it) keeps its world transform at rest: its positions were deformed
  // where it is drawn (as a free piece, following the surface or staying, as the deformer chose).
  // Its transforms are left-multiplied by G'^-1 G (G, G' its joint's rest world matrix before
  // and after); it still rides on the joint in every animation.
  void attachments() {
    const Json& nodes = in_["nodes"];
    for (size_t n = 0; n < parent_.size(); ++n) {
      const int p = parent_[n];
      if (p < 0 || !bind_.count(p) || bind_.count(int(n)) || !nodes[n].contains("mesh") ||
          nodes[n].contains("skin") || joint_below(int(n))) {
        continue;
      }
      const Eigen::Matrix4d before = rest_world(p, false), after = rest_world(p, true);
      correct(int(n), after.inverse() * before, before.topRightCorner<3, 1>().norm(), "mesh node");
    }
  }

  void write_inverse_binds() {
    for (const int s : valid_) {
      const Json& skin = in_["skins"][s];
      const Json& joints = skin["joints"];
      std::vector<float> values(16 * joints.size());
      bool changed = false;
      for (size_t j = 0; j < joints.size(); ++j) {
        const Rigid& T = carried_[json_index(joints[j])];
        const Eigen::Matrix4d was =
            ibm_[s].count > 0 ? column_major(ibm_[s], int(j)) : Eigen::Matrix4d::Identity();
        Eigen::Matrix4d ibm = was;
        if (!(T == Rigid{})) {
          ibm = was * Rigid{T.R.transpose(), -(T.R.transpose() * T.t)}.matrix();  // IBM_j T_j^-1
          changed = true;
        }
        for (int k = 0; k < 16; ++k) values[16 * j + k] = float(ibm(k % 4, k / 4));
      }
      if (!changed) continue;
      const int ibm =
          skin.contains("inverseBindMatrices") ? json_index(skin["inverseBindMatrices"]) : -1;
      if (ibm >= 0 && float_slots(doc_, ibm) && users(ibm) == 1) {
        write_floats(doc_, ibm, values, 16);
      } else if (ibm >= 0) {
        doc_.json["skins"][s]["inverseBindMatrices"] = add_float_accessor(doc_, ibm, values, 16, 0);
      } else {
        const std::string_view bytes(reinterpret_cast<const char*>(values.data()),
                                     values.size() * sizeof(float));
        doc_.json["accessors"].push_back(
            {{"bufferView", doc_.append_view(doc_.data_buffer(), bytes, 0)},
             {"componentType", 5126},
             {"count", joints.size()},
             {"type", "MAT4"}});
        doc_.json["skins"][s]["inverseBindMatrices"] = int(doc_.json["accessors"].size()) - 1;
      }
    }
  }

  void write_nodes() {
    for (const auto& [node, K] : correction_) {
      Json& n = doc_.json["nodes"][node];
      if (n.contains("matrix")) {
        const Eigen::Matrix4d m = K.matrix() * node_matrix(n);
        Json values = Json::array();
        for (int k = 0; k < 16; ++k) values.push_back(m(k % 4, k / 4));
        n["matrix"] = std::move(values);
        continue;
      }
      const Json& t = array_at(n, "translation");
      const Json& r = array_at(n, "rotation");
      const Eigen::Vector3d v =
          t.size() == 3
              ? Eigen::Vector3d(t[0].get<double>(), t[1].get<double>(), t[2].get<double>())
              : Eigen::Vector3d::Zero();
      const Eigen::Quaterniond q = r.size() == 4
                                       ? Eigen::Quaterniond(r[3].get<double>(), r[0].get<double>(),
                                                            r[1].get<double>(), r[2].get<double>())
                                       : Eigen::Quaterniond::Identity();
      const Eigen::Vector3d v2 = K.t + K.R * v;
      const Eigen::Quaterniond q2 = Eigen::Quaterniond(K.R) * q;
      n["translation"] = {v2.x(), v2.y(), v2.z()};
      n["rotation"] = {q2.x(), q2.y(), q2.z(), q2.w()};
    }
  }

  void write_animations() {
    const Json& animations = array_at(in_, "animations");
    for (size_t a = 0; a < animations.size(); ++a) {
      const Json& samplers = array_at(animations[a], "samplers");
      std::map<int, int> channels_of;  // sampler -> channels
      for (const Json& c : array_at(animations[a], "channels"))
        ++channels_of[c.value("sampler", -1)];
      const Json& channels = array_at(animations[a], "channels");
      for (size_t c = 0; c < channels.size(); ++c) {
        const Json& target = object_at(channels[c], "target");
        const int node = target.value("node", -1);
        const std::string path = target.value("path", "");
        const auto K = correction_.find(node);
        if (K == correction_.end() || (path != "translation" && path != "rotation")) continue;
        const int s = channels[c].value("sampler", -1);
        if (s < 0 || size_t(s) >= samplers.size()) doc_.fail("a channel names a missing sampler");
        const int output = json_index(samplers[s]["output"]);
        const bool cubic = samplers[s].value("interpolation", "LINEAR") == "CUBICSPLINE";
        const AccessorValues keys = read_accessor(original_, output, "animation output");
        const int components = path == "rotation" ? 4 : 3;
        if (keys.components != components) doc_.fail("a " + path + " channel of the wrong type");
        std::vector<float> values(keys.values.size());
        const Eigen::Quaterniond turn(K->second.R);
        for (int i = 0; i < keys.count; ++i) {
          const bool tangent = cubic && i % 3 != 1;
          if (path == "rotation") {
            const Eigen::Quaterniond q =
                turn * Eigen::Quaterniond(keys(i, 3), keys(i, 0), keys(i, 1), keys(i, 2));
            const double out[4] = {q.x(), q.y(), q.z(), q.w()};
            for (int k = 0; k < 4; ++k) values[4 * i + k] = float(out[k]);
          } else {
            const Eigen::Vector3d v =
                K->second.R * Eigen::Vector3d(keys(i, 0), keys(i, 1), keys(i, 2)) +
                (tangent ? Eigen::Vector3d::Zero() : K->second.t);
            for (int k = 0; k < 3; ++k) values[3 * i + k] = float(v[k]);
          }
        }
        Json& out_sampler = doc_.json["animations"][a]["samplers"][s];
        if (float_slots(doc_, output) && users(output) == 1 && channels_of[s] == 1) {
          write_floats(doc_, output, values, components);
          set_float_bounds(doc_.json["accessors"][output], values, components, false);
        } else if (channels_of[s] == 1) {
          out_sampler["output"] = add_float_accessor(doc_, output, values, components, 0);
        } else {
          Json copy = out_sampler;
          copy["output"] = add_float_accessor(doc_, output, values, components, 0);
          doc_.json["animations"][a]["samplers"].push_back(std::move(copy));
          doc_.json["animations"][a]["channels"][c]["sampler"] =
              int(doc_.json["animations"][a]["samplers"].size()) - 1;
        }
        ++channels_;
        animations_.insert(int(a));
      }
    }
  }

  std::vector<std::string> notes() const {
    std::vector<std::string> out;
    if (followed_ > 0 || !correction_.empty()) {
      const size_t joints = std::count_if(correction_.begin(), correction_.end(),
                                          [&](const auto& c) { return bind_.count(c.first) > 0; });
      const size_t carried = correction_.size() - joints;
      out.push_back(
          std::to_string(followed_) + " of " + std::to_string(bind_.size()) +
          " joints followed the surface they drive (their inverse bind matrices with them); the "
          "rest transforms of " +
          counted(joints, "joint") +
          (carried > 0 ? " (and of " + counted(carried, "mesh") + " they carry, kept in place)"
                       : std::string()) +
          " and " + counted(channels_, "animation channel") + " (in " +
          counted(animations_.size(), "animation") +
          ") updated, so each part turns about its joint's new place (joints \"keep\" leaves "
          "the skins as they were)");
    }
    if (!skipped_.empty()) {
      std::string names;
      for (const std::string& s : skipped_) names += (names.empty() ? "" : "; ") + s;
      out.push_back("left as the file has them, playing about their old places: " + names);
    }
    return out;
  }

 private:
  // K kept for `node`'s transforms unless it is the identity to rounding (a node riding on its
  // parent); named among the skipped where it is no rigid motion (shear or unequal scales above).
  void correct(int node, const Eigen::Matrix4d& K, double scale, const char* kind) {
    if ((K - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff() <= 1e-10 * (1.0 + scale)) return;
    const Eigen::Matrix3d M = K.topLeftCorner<3, 3>();
    if (!((M.transpose() * M - Eigen::Matrix3d::Identity()).norm() < 1e-6)) {
      skipped_.push_back(std::string(kind) + " " +
                         in_["nodes"][node].value("name", std::to_string(node)) +
                         " (under a transform with shear or unequal scales)");
      return;
    }
    correction_[node] = Rigid{nearest_rotation(M), K.topRightCorner<3, 1>()};
  }

  // A node's world matrix from the nodes' own transforms, with the corrections or without.
  Eigen::Matrix4d rest_world(int node, bool corrected) const {
    Eigen::Matrix4d local = node_matrix(in_["nodes"][node]);
    if (const auto k = correction_.find(node); corrected && k != correction_.end()) {
      local = k->second.matrix() * local;
    }
    return parent_[node] >= 0 ? Eigen::Matrix4d(rest_world(parent_[node], corrected) * local)
                              : local;
  }

  // Whether a joint has `node` among its ancestors.
  bool joint_below(int node) const {
    for (const auto& [joint, B] : bind_)
      for (int up = parent_[joint]; up >= 0; up = parent_[up])
        if (up == node) return true;
    return false;
  }

  // How many references the document's skins and animations make to `accessor`.
  int users(int accessor) const {
    int n = 0;
    for (const Json& skin : array_at(in_, "skins"))
      n += skin.value("inverseBindMatrices", -1) == accessor;
    for (const Json& animation : array_at(in_, "animations"))
      for (const Json& s : array_at(animation, "samplers"))
        n += (s.value("input", -1) == accessor) + (s.value("output", -1) == accessor);
    return n;
  }

  GltfDocument& doc_;
  const GltfDocument& original_;     // as read
  const Json& in_;                   // its JSON
  std::vector<AccessorValues> ibm_;  // per skin (none: identities)
  std::set<int> valid_;              // skins that name their joints and matrices
  std::vector<int> parent_;
  std::map<int, Eigen::Matrix4d> bind_;  // joint node -> B
  std::map<int, Fit> fits_;
  std::vector<Rigid> carried_;       // per node
  std::map<int, Rigid> correction_;  // joint node -> K
  std::vector<std::string> skipped_;
  int followed_ = 0, channels_ = 0;
  std::set<int> animations_;
};

}  // namespace

std::vector<std::string> follow_joints(GltfDocument& doc, const GltfLayout& layout,
                                       const Vertices& rest, const Vertices& positions) {
  Follower follower(doc, layout);
  if (!follower.any_skin()) return {};
  follower.fit(layout, rest, positions);
  follower.motions();
  follower.corrections();
  follower.attachments();
  follower.write_inverse_binds();
  follower.write_nodes();
  follower.write_animations();
  return follower.notes();
}

std::vector<std::string> rig_changes(const GltfDocument& doc) {
  std::vector<std::string> out;
  int targets = 0;
  for (const Json& mesh : array_at(doc.json, "meshes"))
    for (const Json& prim : array_at(mesh, "primitives"))
      targets += int(array_at(prim, "targets").size());
  if (targets > 0) {
    out.push_back(std::to_string(targets) +
                  " morph targets (over the primitives): their deltas turn with the surface "
                  "where it turns (morph targets \"keep\" leaves them)");
  }
  const Json& skins = array_at(doc.json, "skins");
  if (!skins.empty()) {
    std::set<int> joints;
    for (const Json& skin : skins)
      for (const Json& j : array_at(skin, "joints")) joints.insert(json_index(j));
    out.push_back(counted(skins.size(), "skin") + " of " + counted(joints.size(), "joint") +
                  ": the joints of moved vertices follow them, with their inverse bind "
                  "matrices, rest transforms and animation keys (joints \"keep\" leaves them)");
  }
  return out;
}

}  // namespace specdeform::detail
