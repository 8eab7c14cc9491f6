// A drawing's layers as the plotter uses them: choosing some, plotting them one after the other
// with a pause for a pen change between them, each at its own feed (docs/cli.md, "Layers").
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pathstream/host/path.hpp"
#include "pathstream/host/path_order.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

/// The subpaths of the chosen layers (each a layer name, or its number from 1 in the drawing's
/// layer order), the layer list unchanged. Empty `chosen`: the path as it is. Throws
/// std::invalid_argument naming a choice no layer matches and listing the layers there are.
Path select_layers(const Path& path, const std::vector<std::string>& chosen);

/// The subpaths grouped by layer, layers in their order, each layer's subpaths in the order
/// they had (stable). A path without layers is returned as it is. Takes the path by value:
/// pass it moved to sort it in place.
Path group_by_layer(Path path);

/// When a job pauses between layers for a pen change.
enum class LayerPause {
    kPenChange,   ///< between layers whose pens differ (PathLayer::pen; "mixed" differs from all)
    kEveryLayer,  ///< between every two layers
    kNone,
};

/// Sets Subpath::pause_before on the first subpath of a layer that follows another (the path
/// grouped by layer) when `when` says so: the device pauses there, pen up, for a pen change.
void pause_between_layers(Path& path, LayerPause when = LayerPause::kPenChange);

/// Each layer's feed is the profile's layer_feeds entry for its name (entries naming no layer
/// of this drawing are unused; `check` lists every layer's feed), and subpaths with no feed of
/// their own get their layer's.
void apply_layer_feeds(Path& path, const MachineProfile& machine);

/// order_path within each section of the path: the runs of subpaths between pauses and rests
/// (Subpath::pause_before, dwell_before), which keep their place at a section's start; each
/// section starts where the previous one ended. Layers drawn with one pen (no pause between
/// them) are ordered together. `report` covers the whole path.
Path order_sections(Path path, const OrderOptions& options, OrderReport* report = nullptr);

/// Per layer: its name, subpath count and pen-down length (mm), for reports.
struct LayerSummary {
    std::string name;
    std::size_t subpaths = 0;
    double length = 0;
};
std::vector<LayerSummary> summarize_layers(const Path& path);

/// `layers: 2 ("black" 2 subpaths 125.3 mm, "red" 1 subpath 42.4 mm at 20 mm/s), 1 pause`
/// for reports; empty when the path has no layers and no pauses.
std::string layers_text(const Path& path);

/// The same as JSON: [{"name", "subpaths", "drawn_length_mm", "feed_mm_s" (null: the
/// profile's)}], empty without layers.
nlohmann::ordered_json layers_json(const Path& path);

/// Programmed pauses in the path (Subpath::pause_before set).
std::size_t count_pauses(const Path& path);

}  // namespace pathstream::host
