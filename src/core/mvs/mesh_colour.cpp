// A mesh coloured by the photographs (sift_hull/mvs/mesh_colour.h): per view, a z-buffer of the
// mesh's triangles decides which vertices the view sees; each vertex takes the median of their
// colours. Cost: views x (faces rasterised + vertices projected); memory: vertices x views x 4
// bytes for the samples, one image and one z-buffer at a time.

#include "sift_hull/mvs/mesh_colour.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "common/parallel.h"

namespace sift_hull {
namespace {

/// Each vertex in a view at `scale` of its raw pixels (u' = scale (u + 0.5) - 0.5): u', v', depth.
std::vector<Eigen::Vector3d> projectVertices(const TriangleMesh& mesh, const PinholeCamera& camera,
                                             double scale) {
  std::vector<Eigen::Vector3d> projected(mesh.vertices_W.size());
  for (size_t v = 0; v < mesh.vertices_W.size(); ++v) {
    const Eigen::Vector3d X = mesh.vertices_W[v].cast<double>();
    const Eigen::Vector2d px = camera.project(X);
    projected[v] = {scale * (px.x() + 0.5) - 0.5, scale * (px.y() + 0.5) - 0.5, camera.depth(X)};
  }
  return projected;
}

/// Calls visit(face index, u, v, barycentric weights, depth) for every pixel centre of `size`
/// inside a triangle in front of the camera.
template <typename Visit>
void rasterise(const TriangleMesh& mesh, const std::vector<Eigen::Vector3d>& projected,
               cv::Size size, const Visit& visit) {
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3i& face = mesh.faces[f];
    const Eigen::Vector3d &a = projected[face[0]], &b = projected[face[1]], &c = projected[face[2]];
    if (!(a.z() > 0.0 && b.z() > 0.0 && c.z() > 0.0) || !a.allFinite() || !b.allFinite() ||
        !c.allFinite()) {
      continue;
    }
    const double area = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
    if (std::abs(area) < 1e-12) continue;
    const int u0 = std::max(0, static_cast<int>(std::ceil(std::min({a.x(), b.x(), c.x()}))));
    const int u1 =
        std::min(size.width - 1, static_cast<int>(std::floor(std::max({a.x(), b.x(), c.x()}))));
    const int v0 = std::max(0, static_cast<int>(std::ceil(std::min({a.y(), b.y(), c.y()}))));
    const int v1 =
        std::min(size.height - 1, static_cast<int>(std::floor(std::max({a.y(), b.y(), c.y()}))));
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        const double wa = ((b.x() - u) * (c.y() - v) - (c.x() - u) * (b.y() - v)) / area;
        const double wb = ((c.x() - u) * (a.y() - v) - (a.x() - u) * (c.y() - v)) / area;
        const double wc = 1.0 - wa - wb;
        if (wa < 0.0 || wb < 0.0 || wc < 0.0) continue;
        visit(f, u, v, Eigen::Vector3d(wa, wb, wc), wa * a.z() + wb * b.z() + wc * c.z());
      }
    }
  }
}

/// The mesh's depth in a view at `scale` of its raw pixels, +inf where no triangle covers a pixel.
cv::Mat zBuffer(const TriangleMesh& mesh, const PinholeCamera& camera, cv::Size size,
                double scale) {
  cv::Mat depth(size, CV_32FC1, cv::Scalar(std::numeric_limits<float>::infinity()));
  rasterise(mesh, projectVertices(mesh, camera, scale), size,
            [&](size_t, int u, int v, const Eigen::Vector3d&, double z) {
              float& nearest = depth.at<float>(v, u);
              nearest = std::min(nearest, static_cast<float>(z));
            });
  return depth;
}

std::vector<Eigen::Vector3f> vertexNormals(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3f> normals(mesh.vertices_W.size(), Eigen::Vector3f::Zero());
  for (const Eigen::Vector3i& face : mesh.faces) {
    const Eigen::Vector3f n = (mesh.vertices_W[face[1]] - mesh.vertices_W[face[0]])
                                  .cross(mesh.vertices_W[face[2]] - mesh.vertices_W[face[0]]);
    for (int k = 0; k < 3; ++k) normals[face[k]] += n;  // weighted by twice the area
  }
  return normals;
}

double medianEdge(const TriangleMesh& mesh) {
  std::vector<float> edges;
  for (size_t f = 0; f < mesh.faces.size(); f += std::max<size_t>(1, mesh.faces.size() / 4096)) {
    const Eigen::Vector3i& face = mesh.faces[f];
    edges.push_back((mesh.vertices_W[face[1]] - mesh.vertices_W[face[0]]).norm());
  }
  if (edges.empty()) return 0.0;
  std::nth_element(edges.begin(), edges.begin() + edges.size() / 2, edges.end());
  return edges[edges.size() / 2];
}

/// Bilinear BGR at a raw pixel of a CV_8UC3 image; false outside it.
bool sampleBgr(const cv::Mat& bgr, const Eigen::Vector2d& px, std::array<uint8_t, 3>* out) {
  if (!(px.x() >= 0.0 && px.y() >= 0.0 && px.x() <= bgr.cols - 1.0 && px.y() <= bgr.rows - 1.0)) {
    return false;
  }
  const int x0 = std::min(static_cast<int>(px.x()), bgr.cols - 2 < 0 ? 0 : bgr.cols - 2);
  const int y0 = std::min(static_cast<int>(px.y()), bgr.rows - 2 < 0 ? 0 : bgr.rows - 2);
  const int x1 = std::min(x0 + 1, bgr.cols - 1), y1 = std::min(y0 + 1, bgr.rows - 1);
  const double fx = px.x() - x0, fy = px.y() - y0;
  for (int c = 0; c < 3; ++c) {
    const double top = (1 - fx) * bgr.at<cv::Vec3b>(y0, x0)[c] + fx * bgr.at<cv::Vec3b>(y0, x1)[c];
    const double bottom =
        (1 - fx) * bgr.at<cv::Vec3b>(y1, x0)[c] + fx * bgr.at<cv::Vec3b>(y1, x1)[c];
    (*out)[c] = static_cast<uint8_t>(std::lround((1 - fy) * top + fy * bottom));
  }
  return true;
}

cv::Mat bgrOf(const cv::Mat& image) {
  if (image.empty() || image.depth() != CV_8U) {
    throw std::invalid_argument("colouring the mesh: an image that is empty or not 8-bit");
  }
  cv::Mat bgr;
  if (image.channels() == 3) return image;
  if (image.channels() == 1) {
    cv::Mat planes[] = {image, image, image};
    cv::merge(planes, 3, bgr);
    return bgr;
  }
  if (image.channels() == 4) {
    const int from_to[] = {0, 0, 1, 1, 2, 2};
    bgr.create(image.size(), CV_8UC3);
    cv::mixChannels(&image, 1, &bgr, 1, from_to, 3);
    return bgr;
  }
  throw std::invalid_argument("colouring the mesh: an image of " +
                              std::to_string(image.channels()) + " channels");
}

}  // namespace

MeshColouring colourMesh(TriangleMesh* mesh, const std::vector<PinholeCamera>& cameras,
                         const std::function<cv::Mat(uint32_t)>& image, int threads) {
  const size_t vertices = mesh->vertices_W.size(), views = cameras.size();
  // Each vertex's sample per view: B, G, R and whether the view sees it.
  std::vector<std::array<uint8_t, 4>> samples(vertices * views, {0, 0, 0, 0});
  const std::vector<Eigen::Vector3f> normals = vertexNormals(*mesh);
  const double tolerance_m = 2.0 * medianEdge(*mesh);
  for (uint32_t view = 0; view < views; ++view) {
    const cv::Mat bgr = bgrOf(image(view));
    const PinholeCamera& camera = cameras[view];
    const double scale = std::min(1.0, 640.0 / bgr.cols);
    const cv::Size size(std::max(1, static_cast<int>(std::lround(bgr.cols * scale))),
                        std::max(1, static_cast<int>(std::lround(bgr.rows * scale))));
    const cv::Mat depth = zBuffer(*mesh, camera, size, scale);
    const Eigen::Vector3d centre = camera.centre();
    detail::parallelFor((vertices + 4095) / 4096, threads, [&](size_t block) {
      for (size_t v = block * 4096; v < std::min(vertices, (block + 1) * 4096); ++v) {
        const Eigen::Vector3d X = mesh->vertices_W[v].cast<double>();
        const double z = camera.depth(X);
        if (!(z > 0.0) || normals[v].cast<double>().dot(centre - X) <= 0.0) continue;
        const Eigen::Vector2d px = camera.project(X);
        const long u = std::lround(scale * (px.x() + 0.5) - 0.5);
        const long w = std::lround(scale * (px.y() + 0.5) - 0.5);
        if (u < 0 || w < 0 || u >= size.width || w >= size.height) continue;
        // The nearest depth around the pixel: a vertex lies on the border of its triangles.
        float nearest = std::numeric_limits<float>::infinity();
        for (long dv = -1; dv <= 1; ++dv) {
          for (long du = -1; du <= 1; ++du) {
            const long uu = u + du, vv = w + dv;
            if (uu >= 0 && vv >= 0 && uu < size.width && vv < size.height) {
              nearest =
                  std::min(nearest, depth.at<float>(static_cast<int>(vv), static_cast<int>(uu)));
            }
          }
        }
        if (std::isfinite(nearest) && z > nearest + tolerance_m) continue;  // hidden
        std::array<uint8_t, 3> colour;
        if (!sampleBgr(bgr, px, &colour)) continue;
        samples[v * views + view] = {colour[0], colour[1], colour[2], 1};
      }
    });
  }
  MeshColouring result;
  mesh->colours_rgb.assign(vertices, {128, 128, 128});
  std::vector<uint8_t> channel;
  for (size_t v = 0; v < vertices; ++v) {
    std::array<uint8_t, 3> rgb = {128, 128, 128};
    bool seen = false;
    for (int c = 0; c < 3; ++c) {
      channel.clear();
      for (size_t view = 0; view < views; ++view) {
        const std::array<uint8_t, 4>& s = samples[v * views + view];
        if (s[3]) channel.push_back(s[c]);
      }
      if (channel.empty()) break;
      seen = true;
      std::nth_element(channel.begin(), channel.begin() + channel.size() / 2, channel.end());
      rgb[2 - c] = channel[channel.size() / 2];  // B, G, R to red, green, blue
    }
    mesh->colours_rgb[v] = rgb;
    ++(seen ? result.coloured_vertices : result.unseen_vertices);
  }
  return result;
}

MeshRendering renderColouredMesh(const TriangleMesh& mesh, const PinholeCamera& camera,
                                 cv::Size size) {
  if (mesh.colours_rgb.size() != mesh.vertices_W.size()) {
    throw std::invalid_argument("rendering the mesh's colours: it has " +
                                std::to_string(mesh.colours_rgb.size()) + " colours for " +
                                std::to_string(mesh.vertices_W.size()) + " vertices");
  }
  MeshRendering rendering;
  rendering.bgr = cv::Mat(size, CV_8UC3, cv::Scalar::all(0));
  rendering.covered = cv::Mat(size, CV_8UC1, cv::Scalar(0));
  cv::Mat depth(size, CV_32FC1, cv::Scalar(std::numeric_limits<float>::infinity()));
  rasterise(mesh, projectVertices(mesh, camera, 1.0), size,
            [&](size_t f, int u, int v, const Eigen::Vector3d& w, double z) {
              float& nearest = depth.at<float>(v, u);
              if (!(z < nearest)) return;
              nearest = static_cast<float>(z);
              const Eigen::Vector3i& face = mesh.faces[f];
              cv::Vec3b& pixel = rendering.bgr.at<cv::Vec3b>(v, u);
              for (int c = 0; c < 3; ++c) {
                const double value = w[0] * mesh.colours_rgb[face[0]][c] +
                                     w[1] * mesh.colours_rgb[face[1]][c] +
                                     w[2] * mesh.colours_rgb[face[2]][c];
                pixel[2 - c] = cv::saturate_cast<uint8_t>(value);
              }
              rendering.covered.at<uint8_t>(v, u) = 255;
            });
  return rendering;
}

ColourError colourError(const MeshRendering& rendering, const cv::Mat& photo, const cv::Mat& mask) {
  const cv::Mat bgr = bgrOf(photo);
  if (bgr.size() != rendering.bgr.size() || mask.size() != bgr.size() || mask.type() != CV_8UC1) {
    throw std::invalid_argument("colour error: the rendering, photograph and mask differ in size");
  }
  ColourError error;
  double absolute = 0.0, squared = 0.0;
  for (int v = 0; v < bgr.rows; ++v) {
    for (int u = 0; u < bgr.cols; ++u) {
      if (!mask.at<uint8_t>(v, u)) continue;
      const cv::Vec3b a = rendering.bgr.at<cv::Vec3b>(v, u), b = bgr.at<cv::Vec3b>(v, u);
      for (int c = 0; c < 3; ++c) {
        const double d = static_cast<double>(a[c]) - b[c];
        absolute += std::abs(d);
        squared += d * d;
      }
      ++error.pixels;
    }
  }
  if (error.pixels == 0) throw std::invalid_argument("colour error: the silhouette is empty");
  error.mae = absolute / (3.0 * error.pixels);
  const double mse = squared / (3.0 * error.pixels);
  error.psnr_db = mse > 0.0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : 99.0;
  return error;
}

namespace {
/// The key of voxel n (0 .. 26) of the 3x3x3 block around `key`.
octomap::OcTreeKey neighbourKey(const octomap::OcTreeKey& key, int n) {
  octomap::OcTreeKey around = key;
  around[0] = static_cast<octomap::key_type>(around[0] + n % 3 - 1);
  around[1] = static_cast<octomap::key_type>(around[1] + n / 3 % 3 - 1);
  around[2] = static_cast<octomap::key_type>(around[2] + n / 9 - 1);
  return around;
}
}  // namespace

std::unique_ptr<octomap::ColorOcTree> colourOctomap(const octomap::OcTree& tree,
                                                    const TriangleMesh& mesh) {
  if (mesh.colours_rgb.size() != mesh.vertices_W.size()) {
    throw std::invalid_argument("colouring the octree: the mesh has " +
                                std::to_string(mesh.colours_rgb.size()) + " colours for " +
                                std::to_string(mesh.vertices_W.size()) + " vertices");
  }
  auto coloured = std::make_unique<octomap::ColorOcTree>(tree.getResolution());
  coloured->setClampingThresMax(tree.getClampingThresMax());
  coloured->setClampingThresMin(tree.getClampingThresMin());
  coloured->setProbHit(tree.getProbHit());
  coloured->setProbMiss(tree.getProbMiss());
  coloured->setOccupancyThres(tree.getOccupancyThres());
  std::stringstream stream;
  tree.writeBinaryData(stream);
  coloured->readBinaryData(stream);
  // The vertices' colours summed per finest voxel.
  std::unordered_map<octomap::OcTreeKey, std::array<double, 4>, octomap::OcTreeKey::KeyHash> sums;
  for (size_t v = 0; v < mesh.vertices_W.size(); ++v) {
    octomap::OcTreeKey key;
    const Eigen::Vector3f& X = mesh.vertices_W[v];
    if (!coloured->coordToKeyChecked(X.x(), X.y(), X.z(), key)) continue;
    std::array<double, 4>& sum = sums[key];
    for (int c = 0; c < 3; ++c) sum[c] += mesh.colours_rgb[v][c];
    sum[3] += 1.0;
  }
  // The tree is pruned: a block of occupied finest leaves (a flat face along the grid) is one
  // coarser leaf. Each block holding a vertex or one of the 26 voxels around a vertex is expanded
  // down to that voxel (the same occupancy), so that the surface voxels get their own colours. (A
  // vertex on a cell's face may fall in the free voxel beside the occupied one.)
  // (OcTree::setNodeValue would prune the equal children right back.)
  const unsigned finest = coloured->getTreeDepth();
  std::unordered_set<octomap::OcTreeKey, octomap::OcTreeKey::KeyHash> near_vertices;
  for (const auto& voxel : sums) {
    for (int n = 0; n < 27; ++n) near_vertices.insert(neighbourKey(voxel.first, n));
  }
  for (const octomap::OcTreeKey& key : near_vertices) {
    octomap::ColorOcTreeNode* node = coloured->getRoot();
    for (unsigned depth = 0; node != nullptr && depth < finest; ++depth) {
      const unsigned child = octomap::computeChildIdx(key, static_cast<int>(finest - 1 - depth));
      if (!coloured->nodeChildExists(node, child)) {
        // A leaf: expanded when occupied; an unknown child of an inner node: nothing to colour.
        if (coloured->nodeHasChildren(node) || !coloured->isNodeOccupied(node)) break;
        coloured->expandNode(node);
      }
      node = coloured->getNodeChild(node, child);
    }
  }
  for (auto leaf = coloured->begin_leafs(); leaf != coloured->end_leafs(); ++leaf) {
    if (leaf.getDepth() != finest || !coloured->isNodeOccupied(*leaf)) continue;
    const octomap::OcTreeKey key = leaf.getKey();
    std::array<double, 4> total = {0.0, 0.0, 0.0, 0.0};
    const auto own = sums.find(key);
    if (own != sums.end()) total = own->second;  // its own vertices; else those around it
    for (int n = 0; n < 27 && total[3] == 0.0; ++n) {
      const auto found = sums.find(neighbourKey(key, n));
      if (found == sums.end()) continue;
      for (int c = 0; c < 4; ++c) total[c] += found->second[c];
    }
    if (total[3] == 0.0) continue;
    leaf->setColor(static_cast<uint8_t>(std::lround(total[0] / total[3])),
                   static_cast<uint8_t>(std::lround(total[1] / total[3])),
                   static_cast<uint8_t>(std::lround(total[2] / total[3])));
  }
  return coloured;
}

void writeColourOctomap(const octomap::ColorOcTree& tree, const std::string& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << std::setprecision(std::numeric_limits<double>::max_digits10);
  if (!out || !tree.write(out) || !out.flush()) {
    throw std::runtime_error(path + ": cannot write the colour octree");
  }
}

}  // namespace sift_hull
