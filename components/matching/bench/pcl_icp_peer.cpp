// The only file that includes PCL.
#include "pcl_icp_peer.hpp"

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>
#include <pcl/search/kdtree.h>

namespace avs::matching::bench {
namespace {

pcl::PointCloud<pcl::PointXYZ>::Ptr to_pcl(const Points& points) {
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->reserve(points.size());
  for (const auto& p : points) cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  return cloud;
}

}  // namespace

struct PclIcpPeer::Impl {
  pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
  pcl::PointCloud<pcl::PointXYZ>::Ptr model;
  pcl::PointCloud<pcl::PointXYZ>::Ptr scene;
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree;
  pcl::PointCloud<pcl::PointXYZ> output;
};

PclIcpPeer::PclIcpPeer(const Points& model_points_m) : impl_(std::make_unique<Impl>()) {
  impl_->model = to_pcl(model_points_m);
  impl_->tree = pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();
  impl_->tree->setInputCloud(impl_->model);
  impl_->icp.setInputTarget(impl_->model);
  impl_->icp.setSearchMethodTarget(impl_->tree, true);  // prebuilt tree, never recomputed
  impl_->icp.setTransformationEpsilon(0.0);
  impl_->icp.setEuclideanFitnessEpsilon(0.0);
}

PclIcpPeer::~PclIcpPeer() = default;

void PclIcpPeer::set_scene(const Points& p_camera) {
  impl_->scene = to_pcl(p_camera);
  impl_->icp.setInputSource(impl_->scene);
}

Eigen::Isometry3f PclIcpPeer::align(const Eigen::Isometry3f& T_camera_model_guess, int iterations,
                                    float max_correspondence_distance_m) {
  // Source = scene, target = model: PCL estimates T_model_camera, as our ICP does internally.
  impl_->icp.setMaximumIterations(iterations);
  impl_->icp.setMaxCorrespondenceDistance(max_correspondence_distance_m);
  impl_->icp.align(impl_->output, T_camera_model_guess.inverse().matrix());
  Eigen::Isometry3f T_model_camera(impl_->icp.getFinalTransformation());
  return T_model_camera.inverse();
}

}  // namespace avs::matching::bench
