#pragma once
// The osmesa render engine (see osmesa_engine.cpp). Only engines.cpp creates it.

#include <ssx/render.hpp>

#include <memory>

namespace ssx::detail {

class OsmesaRenderEngine final : public RenderEngine {
 public:
  OsmesaRenderEngine();
  ~OsmesaRenderEngine() override;
  std::string name() const override { return "osmesa"; }
  bool drawsPixels() const override { return true; }
  void renderView(const CameraView& view, const std::vector<RenderNode>& nodes, const Color& background,
                  Image& out) override;

 private:
  struct Gl;
  void makeCurrent(int width, int height);
  void setup();
  std::unique_ptr<Gl> gl_;
};

}  // namespace ssx::detail
