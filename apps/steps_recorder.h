// The stage stepper's observer (focal steps, focal probe): turns the stages and probes a
// dof::FrameRenderer reports (dof/frame_observer.h) into the JSON of docs/steps-format.md and,
// when given a folder, into pictures there (PNG, 8-bit sRGB, false colours for numbers).
// Consumes the borrowed stages during the callbacks; owns the JSON it builds.
#pragma once

#include <dof/frame_observer.h>
#include <raster/camera.h>
#include <raster/status.h>

#include <glm/vec2.hpp>
#include <nlohmann/json.hpp>

#include <span>
#include <string>
#include <vector>

namespace focal {

class StepsRecorder final : public dof::FrameObserver {
public:
    // `folder`: where images/NAME.png go (files named relative to it in the JSON); empty: no
    // pictures (focal probe). `probes`: the pixels to probe, in the order reported.
    StepsRecorder(std::string folder, std::vector<glm::uvec2> probes);

    std::span<const glm::uvec2> probePixels() override { return probes_; }
    void stage(const dof::Stage& stage) override;
    void probe(const dof::PixelProbe& probe) override;

    nlohmann::json& stages() { return stages_; }
    nlohmann::json& probes() { return probe_json_; }
    // The first failure writing a picture (the callbacks cannot return one).
    const raster::Status& status() const { return status_; }

private:
    std::string folder_;
    std::vector<glm::uvec2> probes_;
    nlohmann::json stages_ = nlohmann::json::array();
    nlohmann::json probe_json_ = nlohmann::json::array();
    raster::Status status_;
};

// A JSON number for a float that may be infinite or NaN (JSON has neither): null then.
nlohmann::json finiteOrNull(double v);
nlohmann::json finiteOrNull(float v);

} // namespace focal
