#include "vdyn/core/animation.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

// tinygltf (Debian's libtinygltf-dev, header-only): its implementation is
// compiled here once; no images, so none of its image code.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include "vdyn/core/error.h"
#include "vdyn/core/file_io.h"
#include "vdyn/core/params.h"
#include "vdyn/core/scene.h"

namespace vdyn {

namespace {

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

/// `points_B`: where the body is joined to others (its mobilizer frame M, its
/// children's inboard frames F), in B, m.
AnimationShape shapeOf(const std::string& name, const SimTK::MassProperties& mp,
                       const std::vector<SimTK::Vec3>& points_B) {
  AnimationShape shape;
  const double m = mp.getMass();  // kg
  if (!(m > 0)) return shape;     // massless (a steering's virtual body): not drawn
  shape.centre_B = mp.getMassCenter();
  const SimTK::Vec3 I = mp.calcCentralInertia().getMoments();  // about the mass centre, along B's axes, kg m^2
  if (endsWith(name, "wheel") || name == "front_axle" || name == "rear_axle") {
    // A wheel: spin axis B's y; I_yy = m r^2 / 2 of a disc, width from I_xx = m (3 r^2 + w^2) / 12.
    const double r = std::sqrt(2 * I[1] / m);
    const double w2 = 12 * I[0] / m - 3 * r * r;
    shape.kind = AnimationShape::Cylinder;
    shape.size_m = {r, std::clamp(w2 > 0 ? std::sqrt(w2) : 0.0, 0.15, 0.4), 0};
    shape.colour = {0.12, 0.12, 0.12};
    return shape;
  }
  shape.kind = AnimationShape::Box;
  shape.colour = name == "chassis" ? SimTK::Vec3(0.85, 0.12, 0.08) : SimTK::Vec3(0.2, 0.4, 0.85);
  if (name != "chassis" && std::max({I[0], I[1], I[2]}) <= 1.01 * std::min({I[0], I[1], I[2]})) {
    // A spherical inertia says nothing of the shape (an arm's lumped data):
    // a link, 4 cm thick, between the two farthest of its joints and mass
    // centre, axis-aligned in B; a 10 cm cube where they coincide.
    std::vector<SimTK::Vec3> pts = points_B;
    pts.push_back(shape.centre_B);
    SimTK::Vec3 a = pts[0], b = pts[0];
    for (const auto& p : pts)
      for (const auto& q : pts)
        if ((p - q).norm() > (a - b).norm()) a = p, b = q;
    shape.centre_B = (a + b) / 2;
    for (int i = 0; i < 3; ++i) shape.size_m[i] = std::max(std::abs(a[i] - b[i]), 0.04);
    if ((a - b).norm() < 0.05) shape.size_m = SimTK::Vec3(0.1);
    return shape;
  }
  // The box of the same central inertia: a_x^2 = 6 (I_yy + I_zz - I_xx) / m, ...
  for (int i = 0; i < 3; ++i) {
    const double a2 = 6 * (I[(i + 1) % 3] + I[(i + 2) % 3] - I[i]) / m;
    shape.size_m[i] = std::max(a2 > 0 ? std::sqrt(a2) : 0.0, 0.03);
  }
  if (name == "chassis") {
    // The chassis's box clear of the wheels: no wider than its innermost
    // joint off the centre plane (|y| > 0.1 m, the suspension's inboard
    // points), its bottom no lower than the mean height of its joints more
    // than 0.3 m from the mass centre horizontally (suspension points, a
    // single-track model's axles).
    double halfWidth = shape.size_m[1] / 2, zSum = 0;
    int n = 0;
    for (const auto& p : points_B) {
      const SimTK::Vec3 d = p - shape.centre_B;
      if (std::abs(d[1]) > 0.1) halfWidth = std::min(halfWidth, std::abs(d[1]));
      if (std::hypot(d[0], d[1]) > 0.3) zSum += p[2], ++n;
    }
    const double top = shape.centre_B[2] + shape.size_m[2] / 2;
    const double bottom = std::max(shape.centre_B[2] - shape.size_m[2] / 2, n ? zSum / n : -INFINITY);
    shape.size_m[1] = 2 * halfWidth;
    if (top - bottom > 0.1) shape.centre_B[2] = (top + bottom) / 2, shape.size_m[2] = top - bottom;
  }
  return shape;
}

/// Triangles of a shape in B: positions, normals (float32, m) and indices.
struct MeshData {
  std::vector<float> pos, nrm;
  std::vector<std::uint16_t> idx;
  void vertex(const SimTK::Vec3& p, const SimTK::Vec3& n) {
    for (int i = 0; i < 3; ++i) pos.push_back(float(p[i])), nrm.push_back(float(n[i]));
  }
};

MeshData boxMesh(const AnimationShape& s) {
  MeshData m;
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {-1, 1}) {
      SimTK::Vec3 n(0);
      n[axis] = sign;
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const auto base = std::uint16_t(m.pos.size() / 3);
      for (int k = 0; k < 4; ++k) {
        SimTK::Vec3 p(0);
        p[axis] = sign * s.size_m[axis] / 2;
        p[u] = ((k == 1 || k == 2) ? 1 : -1) * s.size_m[u] / 2;
        p[v] = (k >= 2 ? 1 : -1) * s.size_m[v] / 2;
        m.vertex(s.centre_B + p, n);
      }
      // Counter-clockwise seen from outside (n = u x v for sign > 0).
      const std::uint16_t a[6] = {0, 1, 2, 0, 2, 3}, b[6] = {0, 2, 1, 0, 3, 2};
      for (int k = 0; k < 6; ++k) m.idx.push_back(std::uint16_t(base + (sign > 0 ? a[k] : b[k])));
    }
  return m;
}

/// A cylinder about B's y (radius size_m[0], width size_m[1]) or, with
/// `tip`, a cone standing on B's xy plane along z (radius size_m[0], height size_m[1]).
MeshData roundMesh(const AnimationShape& s, bool cone) {
  MeshData m;
  const int n = 32;
  const double r = s.size_m[0], w = s.size_m[1];
  auto at = [&](double ang, double along) {
    return cone ? SimTK::Vec3(r * std::cos(ang), r * std::sin(ang), along)
                : SimTK::Vec3(r * std::cos(ang), along, r * std::sin(ang));
  };
  const SimTK::Vec3 axis = cone ? SimTK::Vec3(0, 0, 1) : SimTK::Vec3(0, 1, 0);
  for (int i = 0; i <= n; ++i) {
    const double ang = 2 * SimTK::Pi * i / n;
    const SimTK::Vec3 radial = at(ang, 0) / r;
    if (cone) {
      m.vertex(s.centre_B + at(ang, 0), radial);
      m.vertex(s.centre_B + w * axis, radial);
    } else {
      m.vertex(s.centre_B + at(ang, -w / 2), radial);
      m.vertex(s.centre_B + at(ang, w / 2), radial);
    }
  }
  for (int i = 0; i < n; ++i) {
    const auto a = std::uint16_t(2 * i);
    for (std::uint16_t k : {0, 2, 1, 1, 2, 3}) m.idx.push_back(std::uint16_t(a + k));
  }
  // Caps (the cone's base only): a centre and a ring each.
  for (int side : cone ? std::vector<int>{-1} : std::vector<int>{-1, 1}) {
    const auto base = std::uint16_t(m.pos.size() / 3);
    const SimTK::Vec3 nrm = double(side) * axis;
    const double along = cone ? 0.0 : side * w / 2;
    m.vertex(s.centre_B + along * axis, nrm);
    for (int i = 0; i <= n; ++i) m.vertex(s.centre_B + at(2 * SimTK::Pi * i / n, along), nrm);
    for (int i = 0; i < n; ++i) {
      m.idx.push_back(base);
      m.idx.push_back(std::uint16_t(base + 1 + (side > 0 ? i + 1 : i)));
      m.idx.push_back(std::uint16_t(base + 1 + (side > 0 ? i : i + 1)));
    }
  }
  return m;
}

/// Builds the glTF model's one buffer and its views and accessors.
struct GlbBuilder {
  tinygltf::Model model;
  std::vector<unsigned char> bin;

  int view(const void* data, std::size_t bytes, int target = 0) {
    while (bin.size() % 8) bin.push_back(0);  // aligned for float64 views too
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = bin.size();
    v.byteLength = bytes;
    v.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    bin.insert(bin.end(), p, p + bytes);
    model.bufferViews.push_back(v);
    return int(model.bufferViews.size() - 1);
  }
  int accessor(const std::vector<float>& values, int type, int components, int target = 0, bool minMax = false) {
    tinygltf::Accessor a;
    a.bufferView = view(values.data(), values.size() * sizeof(float), target);
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.count = values.size() / components;
    a.type = type;
    if (minMax && a.count > 0) {
      a.minValues.assign(components, INFINITY);
      a.maxValues.assign(components, -INFINITY);
      for (std::size_t i = 0; i < values.size(); ++i) {
        a.minValues[i % components] = std::min(a.minValues[i % components], double(values[i]));
        a.maxValues[i % components] = std::max(a.maxValues[i % components], double(values[i]));
      }
    }
    model.accessors.push_back(a);
    return int(model.accessors.size() - 1);
  }
  int indices(const std::vector<std::uint16_t>& idx) {
    tinygltf::Accessor a;
    a.bufferView = view(idx.data(), idx.size() * sizeof(std::uint16_t), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    a.count = idx.size();
    a.type = TINYGLTF_TYPE_SCALAR;
    model.accessors.push_back(a);
    return int(model.accessors.size() - 1);
  }
  int material(const std::string& name, const SimTK::Vec3& rgb) {
    tinygltf::Material m;
    m.name = name;
    m.pbrMetallicRoughness.baseColorFactor = {rgb[0], rgb[1], rgb[2], 1.0};
    m.pbrMetallicRoughness.metallicFactor = 0.0;
    m.pbrMetallicRoughness.roughnessFactor = 0.8;
    model.materials.push_back(m);
    return int(model.materials.size() - 1);
  }
  int triangles(const std::string& name, const MeshData& d, int mat) {
    tinygltf::Primitive p;
    p.attributes["POSITION"] = accessor(d.pos, TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
    p.attributes["NORMAL"] = accessor(d.nrm, TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER);
    p.indices = indices(d.idx);
    p.material = mat;
    p.mode = TINYGLTF_MODE_TRIANGLES;
    tinygltf::Mesh mesh;
    mesh.name = name;
    mesh.primitives.push_back(p);
    model.meshes.push_back(mesh);
    return int(model.meshes.size() - 1);
  }
  int node(const std::string& name, int mesh) {
    tinygltf::Node n;
    n.name = name;
    n.mesh = mesh;
    model.nodes.push_back(n);
    return int(model.nodes.size() - 1);
  }
};

/// q_GB as glTF's (x, y, z, w), the sign chosen nearest `previous` (so LINEAR
/// interpolation between samples takes the short way).
SimTK::Vec4 quaternionXyzw(const SimTK::Rotation& R_GB, const SimTK::Vec4& previous) {
  const SimTK::Quaternion q = R_GB.convertRotationToQuaternion();  // (w, x, y, z)
  SimTK::Vec4 xyzw(q[1], q[2], q[3], q[0]);
  if (~xyzw * previous < 0) xyzw = -xyzw;
  return xyzw;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot read '" + path + "'");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string base64(const std::string& bytes) {
  static const char* abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 3; ++k) v = (v << 8) | (k < n ? std::uint8_t(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? abc[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

void replaceOnce(std::string& text, const std::string& key, const std::string& value) {
  const auto at = text.find(key);
  if (at == std::string::npos) throw Error("animation viewer template: no " + key);
  text.replace(at, key.size(), value);
}

// The viewer: a classic script turns the inlined three.js files into blob
// module URLs (three.module.js imports './three.core.js'), imports them, reads
// the inlined .glb (its JSON and binary chunks: meshes, materials, node TRS,
// the animation's channels) into a three.js scene and an AnimationMixer.
const char* kViewer = R"HTML(<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>__TITLE__</title>
<style>
 html, body { margin: 0; height: 100%; overflow: hidden; font: 14px sans-serif; background: #eef1f4; }
 #view { position: absolute; inset: 0; }
 #bar { position: absolute; left: 0; right: 0; bottom: 0; display: flex; gap: 8px; align-items: center;
        padding: 6px 10px; background: rgba(255,255,255,0.85); }
 #slider { flex: 1; }
 #status { position: absolute; top: 6px; left: 10px; color: #333; }
</style></head>
<body>
<div id="view"></div>
<div id="status">__TITLE__</div>
<div id="bar"><button id="play">Play</button><input id="slider" type="range" min="0" max="1" step="0.001" value="0">
<span id="time">t = 0.000 s</span></div>
<script id="three-core" type="application/octet-stream">__THREE_CORE__</script>
<script id="three-module" type="application/octet-stream">__THREE_MODULE__</script>
<script id="glb" type="application/octet-stream">__GLB__</script>
<script>
"use strict";
function bytesOf(id) {
  const s = atob(document.getElementById(id).textContent.trim());
  const b = new Uint8Array(s.length);
  for (let i = 0; i < s.length; ++i) b[i] = s.charCodeAt(i);
  return b;
}
function moduleUrl(text) { return URL.createObjectURL(new Blob([text], {type: "text/javascript"})); }
const coreUrl = moduleUrl(bytesOf("three-core"));
const moduleText = new TextDecoder().decode(bytesOf("three-module")).split("'./three.core.js'").join("'" + coreUrl + "'");
import(moduleUrl(moduleText)).then(main).catch(e => { document.getElementById("status").textContent = "viewer: " + e; });

function main(THREE) {
  const glb = bytesOf("glb");
  const dv = new DataView(glb.buffer);
  const jsonLength = dv.getUint32(12, true);
  const gltf = JSON.parse(new TextDecoder().decode(glb.subarray(20, 20 + jsonLength)));
  const binStart = 20 + jsonLength + 8;
  const kinds = {SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4};
  const arrays = {5126: Float32Array, 5123: Uint16Array, 5125: Uint32Array};
  function accessor(i) {
    const a = gltf.accessors[i], v = gltf.bufferViews[a.bufferView], T = arrays[a.componentType];
    const start = binStart + (v.byteOffset || 0) + (a.byteOffset || 0);
    return new T(glb.buffer.slice(start, start + a.count * kinds[a.type] * T.BYTES_PER_ELEMENT));
  }
  const materials = (gltf.materials || []).map(m => {
    const c = m.pbrMetallicRoughness.baseColorFactor;
    return new THREE.Color(c[0], c[1], c[2]);
  });
  function object(i) {
    const n = gltf.nodes[i];
    let o = new THREE.Group();
    if (n.mesh !== undefined) {
      o = new THREE.Group();
      for (const p of gltf.meshes[n.mesh].primitives) {
        const g = new THREE.BufferGeometry();
        g.setAttribute("position", new THREE.BufferAttribute(accessor(p.attributes.POSITION), 3));
        if (p.attributes.NORMAL !== undefined) g.setAttribute("normal", new THREE.BufferAttribute(accessor(p.attributes.NORMAL), 3));
        if (p.indices !== undefined) g.setIndex(new THREE.BufferAttribute(accessor(p.indices), 1));
        const colour = p.material !== undefined ? materials[p.material] : new THREE.Color(0.5, 0.5, 0.5);
        if (p.mode === 3) o.add(new THREE.Line(g, new THREE.LineBasicMaterial({color: colour})));
        else o.add(new THREE.Mesh(g, new THREE.MeshLambertMaterial({color: colour})));
      }
    }
    o.name = n.name || ("node" + i);
    if (n.translation) o.position.fromArray(n.translation);
    if (n.rotation) o.quaternion.fromArray(n.rotation);
    for (const c of n.children || []) o.add(object(c));
    nodes[i] = o;
    return o;
  }
  const nodes = [];
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xeef1f4);
  for (const i of gltf.scenes[gltf.scene || 0].nodes) scene.add(object(i));
  scene.add(new THREE.HemisphereLight(0xffffff, 0x888888, 2.0));
  const sun = new THREE.DirectionalLight(0xffffff, 1.5);
  sun.position.set(-5, 10, 7);
  scene.add(sun);
  // The ground: a plane and an 80 m grid of 1 m on it (moved with the vehicle, in 10 m steps).
  const grid = new THREE.Group();
  const plane = new THREE.Mesh(new THREE.PlaneGeometry(400, 400), new THREE.MeshBasicMaterial({color: 0xdfe3e8}));
  plane.rotation.x = -Math.PI / 2;
  plane.position.y = -0.005;
  grid.add(plane);
  // In 1 m segments: a long line that passes behind the camera is lost by
  // some GL implementations' clipping (SwiftShader's).
  const lines = [];
  for (let i = -40; i <= 40; ++i)
    for (let j = -40; j < 40; ++j) lines.push(i, 0, j, i, 0, j + 1, j, 0, i, j + 1, 0, i);
  const gridGeometry = new THREE.BufferGeometry();
  gridGeometry.setAttribute("position", new THREE.Float32BufferAttribute(lines, 3));
  grid.add(new THREE.LineSegments(gridGeometry, new THREE.LineBasicMaterial({color: 0xa8adb4})));
  scene.add(grid);

  const tracks = [];
  let tEnd = 0;
  const anim = (gltf.animations || [])[0];
  if (anim) for (const ch of anim.channels) {
    const s = anim.samplers[ch.sampler], times = accessor(s.input), values = accessor(s.output);
    tEnd = Math.max(tEnd, times[times.length - 1]);
    const target = nodes[ch.target.node].uuid;
    if (ch.target.path === "translation") tracks.push(new THREE.VectorKeyframeTrack(target + ".position", times, values));
    if (ch.target.path === "rotation") tracks.push(new THREE.QuaternionKeyframeTrack(target + ".quaternion", times, values));
  }
  const mixer = new THREE.AnimationMixer(scene);
  mixer.clipAction(new THREE.AnimationClip("run", tEnd, tracks)).play();
  const followed = scene.getObjectByName("chassis") || nodes[(gltf.scenes[0].nodes[0])];

  const view = document.getElementById("view");
  const renderer = new THREE.WebGLRenderer({antialias: true, preserveDrawingBuffer: true});
  renderer.setPixelRatio(window.devicePixelRatio);
  view.appendChild(renderer.domElement);
  const camera = new THREE.PerspectiveCamera(40, 1, 0.1, 1000);
  const slider = document.getElementById("slider"), label = document.getElementById("time");
  slider.max = tEnd;
  slider.step = tEnd / 2000;
  let t = 0, playing = false, last = 0;
  function show(time) {
    t = Math.min(Math.max(time, 0), tEnd);
    mixer.setTime(t);
    scene.updateMatrixWorld(true);
    const c = new THREE.Vector3();
    followed.getWorldPosition(c);
    // Behind the vehicle's right side, above (three.js is y-up; ground's x is three's x, ground's y is three's -z).
    camera.position.set(c.x - 7, c.y + 4, c.z + 7);
    camera.lookAt(c);
    grid.position.set(Math.round(c.x / 10) * 10, 0, Math.round(c.z / 10) * 10);
    slider.value = t;
    label.textContent = "t = " + t.toFixed(3) + " s";
    renderer.setSize(view.clientWidth, view.clientHeight);
    camera.aspect = view.clientWidth / view.clientHeight;
    camera.updateProjectionMatrix();
    renderer.render(scene, camera);
  }
  function tick(now) {
    if (!playing) return;
    const dt = last ? (now - last) / 1000 : 0;
    last = now;
    show(t + dt >= tEnd ? tEnd : t + dt);
    if (t >= tEnd) { playing = false; document.getElementById("play").textContent = "Play"; return; }
    requestAnimationFrame(tick);
  }
  document.getElementById("play").onclick = () => {
    playing = !playing;
    document.getElementById("play").textContent = playing ? "Pause" : "Play";
    if (playing) { if (t >= tEnd) t = 0; last = 0; requestAnimationFrame(tick); }
  };
  slider.oninput = () => { playing = false; document.getElementById("play").textContent = "Play"; show(parseFloat(slider.value)); };
  window.onresize = () => show(t);
  const m = /[#&]t=([0-9.eE+-]+)/.exec(location.hash);
  show(m ? parseFloat(m[1]) : 0);
  document.title = document.title + " (ready)";
}
</script>
</body></html>
)HTML";

}  // namespace

void AnimationRecorder::restart(const Scene& scene) {
  bodies_.clear();
  names_.clear();
  shapes_.clear();
  decorations_ = SceneDecorations();
  time_s_.clear();
  poses_.clear();
  const SimTK::SimbodyMatterSubsystem& matter = scene.getMatter();
  std::map<int, std::string> named;  // mobilized body index -> first name (a body may have two)
  for (const auto& n : scene.getBodyNames()) named.emplace(int(scene.getBody(n).getMobilizedBodyIndex()), n);
  std::vector<std::vector<SimTK::Vec3>> joints_B(matter.getNumBodies());  // per body: its joints in B, m
  for (SimTK::MobilizedBodyIndex b(1); b < matter.getNumBodies(); ++b) {
    const SimTK::MobilizedBody& mb = matter.getMobilizedBody(b);
    joints_B[b].push_back(mb.getDefaultOutboardFrame().p());                                    // p_BM
    joints_B[mb.getParentMobilizedBody().getMobilizedBodyIndex()].push_back(mb.getDefaultInboardFrame().p());  // p_PF
  }
  for (SimTK::MobilizedBodyIndex b(1); b < matter.getNumBodies(); ++b) {
    const auto it = named.find(int(b));
    bodies_.push_back(b);
    names_.push_back(it != named.end() ? it->second : "body" + std::to_string(int(b)));
    shapes_.push_back(
        shapeOf(names_.back(), matter.getMobilizedBody(b).getBody().getDefaultRigidBodyMassProperties(), joints_B[b]));
  }
  for (const auto& p : scene.getPlugins()) p->addDecorations(decorations_);
  matter_ = &matter;
}

void AnimationRecorder::sample(const SimTK::State& state) {
  const double t = state.getTime();
  if (!time_s_.empty() && !(t > time_s_.back())) {
    time_s_.clear();
    poses_.clear();
  }
  time_s_.push_back(t);
  for (SimTK::MobilizedBodyIndex b : bodies_) poses_.push_back(matter_->getMobilizedBody(b).getBodyTransform(state));
}

std::string AnimationRecorder::makeGlb() const {
  if (time_s_.empty()) throw Error("animation: nothing was recorded");
  GlbBuilder g;
  g.model.asset.version = "2.0";
  g.model.asset.generator = "vdyn";
  const int ground = g.node("ground", -1);
  // Simbody's ground is z-up, glTF's y-up: -90 deg about x.
  g.model.nodes[ground].rotation = {-std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)};
  std::vector<int> children, bodyNodes;
  std::map<std::string, int> materials;
  for (std::size_t b = 0; b < names_.size(); ++b) {
    const AnimationShape& s = shapes_[b];
    int mesh = -1;
    if (s.kind != AnimationShape::None) {
      const int mat = g.material(names_[b], s.colour);
      mesh = g.triangles(names_[b], s.kind == AnimationShape::Box ? boxMesh(s) : roundMesh(s, false), mat);
    }
    const int node = g.node(names_[b], mesh);
    const SimTK::Transform& X = pose(0, b);
    const SimTK::Vec4 q = quaternionXyzw(X.R(), SimTK::Vec4(0, 0, 0, 1));
    g.model.nodes[node].translation = {X.p()[0], X.p()[1], X.p()[2]};
    g.model.nodes[node].rotation = {q[0], q[1], q[2], q[3]};
    bodyNodes.push_back(node);
    children.push_back(node);
  }
  if (!decorations_.lines.empty()) {
    const int mat = g.material("path", {0.1, 0.6, 0.2});
    for (const auto& line : decorations_.lines) {
      std::vector<float> pos;
      for (const SimTK::Vec3& p : line.p_G) pos.insert(pos.end(), {float(p[0]), float(p[1]), float(p[2] + 0.01)});
      tinygltf::Primitive prim;
      prim.attributes["POSITION"] = g.accessor(pos, TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
      prim.material = mat;
      prim.mode = TINYGLTF_MODE_LINE_STRIP;
      tinygltf::Mesh mesh;
      mesh.name = line.name;
      mesh.primitives.push_back(prim);
      g.model.meshes.push_back(mesh);
      children.push_back(g.node(line.name, int(g.model.meshes.size() - 1)));
    }
  }
  if (!decorations_.cones_G.empty()) {
    AnimationShape cone;
    cone.size_m = {decorations_.cone_base_radius_m, decorations_.cone_height_m, 0};  // base radius, height, m
    const int mesh = g.triangles("cone", roundMesh(cone, true), g.material("cone", {1.0, 0.45, 0.0}));
    for (std::size_t i = 0; i < decorations_.cones_G.size(); ++i) {
      const int node = g.node("cone" + std::to_string(i), mesh);
      const SimTK::Vec3& p = decorations_.cones_G[i];
      g.model.nodes[node].translation = {p[0], p[1], p[2]};
      children.push_back(node);
    }
  }
  g.model.nodes[ground].children = children;

  // The animation: float32 keyframes at the sample times.
  const std::size_t n = time_s_.size(), nb = names_.size();
  std::vector<float> times(time_s_.begin(), time_s_.end());
  const int input = g.accessor(times, TINYGLTF_TYPE_SCALAR, 1, 0, true);
  tinygltf::Animation anim;
  anim.name = "run";
  for (std::size_t b = 0; b < nb; ++b) {
    std::vector<float> p, r;
    SimTK::Vec4 prev(0, 0, 0, 1);
    for (std::size_t k = 0; k < n; ++k) {
      const SimTK::Transform& X = pose(k, b);
      prev = quaternionXyzw(X.R(), prev);
      for (int i = 0; i < 3; ++i) p.push_back(float(X.p()[i]));
      for (int i = 0; i < 4; ++i) r.push_back(float(prev[i]));
    }
    const int out[2] = {g.accessor(p, TINYGLTF_TYPE_VEC3, 3), g.accessor(r, TINYGLTF_TYPE_VEC4, 4)};
    const char* paths[2] = {"translation", "rotation"};
    for (int c = 0; c < 2; ++c) {
      tinygltf::AnimationSampler s;
      s.input = input;
      s.output = out[c];
      s.interpolation = "LINEAR";
      anim.samplers.push_back(s);
      tinygltf::AnimationChannel ch;
      ch.sampler = int(anim.samplers.size() - 1);
      ch.target_node = bodyNodes[b];
      ch.target_path = paths[c];
      anim.channels.push_back(ch);
    }
  }
  g.model.animations.push_back(anim);

  // The exact poses, float64 (no accessor: glTF has no float64 accessors).
  std::vector<double> X64;
  X64.reserve(n * nb * 12);
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t b = 0; b < nb; ++b) {
      const SimTK::Transform& X = pose(k, b);
      for (int i = 0; i < 3; ++i) X64.push_back(X.p()[i]);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) X64.push_back(X.R()[i][j]);
    }
  const int timeView = g.view(time_s_.data(), n * sizeof(double));
  const int poseView = g.view(X64.data(), X64.size() * sizeof(double));
  using V = tinygltf::Value;
  V::Array bodies, nodes;
  for (std::size_t b = 0; b < nb; ++b) bodies.push_back(V(names_[b])), nodes.push_back(V(bodyNodes[b]));
  V::Object vdyn;
  vdyn["bodies"] = V(bodies);
  vdyn["body_nodes"] = V(nodes);
  vdyn["samples"] = V(int(n));
  vdyn["time_s_f64_bufferView"] = V(timeView);
  vdyn["X_GB_f64_bufferView"] = V(poseView);
  vdyn["X_GB_f64_layout"] = V(std::string(
      "little-endian float64, sample-major, then body in 'bodies' order: p_GB (x, y, z; m, in G), then R_GB row-major "
      "(9; ground frame G is z-up, the node 'ground' turns it y-up)"));
  V::Object extras;
  extras["vdyn"] = V(vdyn);
  g.model.asset.extras = V(extras);

  tinygltf::Buffer buffer;
  buffer.data = g.bin;
  g.model.buffers.push_back(buffer);
  tinygltf::Scene scene;
  scene.nodes = {ground};
  g.model.scenes.push_back(scene);
  g.model.defaultScene = 0;
  std::ostringstream os;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&g.model, os, false, true)) throw Error("animation: tinygltf could not write the .glb");
  return os.str();
}

std::string findThreeJs() {
  std::vector<std::string> tried;
  if (const char* env = std::getenv("VDYN_THREE_DIR")) tried.push_back(env);
#ifdef VDYN_BUILD_THREE_DIR
  tried.push_back(VDYN_BUILD_THREE_DIR);
#endif
  for (const auto& d : dataSearchPath()) tried.push_back(d + "/viewer/three");
  std::string list;
  for (const auto& d : tried) {
    if (std::filesystem::exists(d + "/three.module.js") && std::filesystem::exists(d + "/three.core.js")) return d;
    list += (list.empty() ? "" : ", ") + d;
  }
  throw Error("animation viewer: three.js (three.module.js, three.core.js) not found in " + list +
              " (the build installs it with npm; VDYN_THREE_DIR names another folder)");
}

std::string makeAnimationViewer(const std::string& glb, const std::string& title) {
  const std::string dir = findThreeJs();
  std::string html = kViewer;
  std::string safeTitle;
  for (char c : title) safeTitle += (c == '<' || c == '>' || c == '&') ? '_' : c;
  replaceOnce(html, "__TITLE__", safeTitle);
  replaceOnce(html, "__TITLE__", safeTitle);
  replaceOnce(html, "__THREE_CORE__", base64(readFile(dir + "/three.core.js")));
  replaceOnce(html, "__THREE_MODULE__", base64(readFile(dir + "/three.module.js")));
  replaceOnce(html, "__GLB__", base64(glb));
  return html;
}

std::vector<std::string> writeAnimation(const AnimationRecorder& recorder, const std::string& stem,
                                        const std::string& title) {
  const std::string glb = recorder.makeGlb();
  const std::string html = makeAnimationViewer(glb, title);
  writeFileAtomic(stem + ".glb", glb);
  writeFileAtomic(stem + ".html", html);
  return {stem + ".glb", stem + ".html"};
}

}  // namespace vdyn
