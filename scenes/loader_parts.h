// The parts of the scene loader that call each other across files, internal to the scene
// library: the [system] dispatch (scene_loader.cpp), the systems read from other file formats
// (scene_imports.cpp), the catalog meta-type (scene_catalog.cpp) and the settings tables
// (scene_settings.cpp). The system types themselves are in scenes/systems/ (system_types.h).
#pragma once

#include <toml++/toml.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "engine/model.h"
#include "scenes/importers.h"
#include "scenes/scene.h"
#include "scenes/toml_reader.h"

namespace flexure::scenes::detail {

// The model of a [system] table: from = FILE, type = "catalog" or one of the system types.
// `type_out` receives the type built; `depth` counts catalog entries naming entries; `resolved`
// (when given) receives the [system] table a file or catalog entry stands for.
std::unique_ptr<engine::Model> buildModel(const Reader& r, const toml::table& sys, int base,
                                          std::string& type_out, int depth, toml::table* resolved = nullptr);

// scene_imports.cpp

// A file a scene names (`from`), relative to the scene file's folder unless absolute.
std::string besideScene(const std::string& scene_file, const std::string& name);

// A graph's seeded random realization (dimension x vertices): uniform in the unit square or
// cube, vertex by vertex, from the seed.
engine::Matrix graphRealization(int vertices, int dimension, std::uint64_t seed);

// A graph's framework table (type, vertices, edges) at graphRealization, or at the positions
// the file gives. Vertex numbers from `base`.
toml::table graphSystem(const ImportedGraph& g, int dimension, std::uint64_t seed, int base);

// [system] from = "FILE": the system of a graph, mesh or FOLD file.
std::unique_ptr<engine::Model> buildImported(const Reader& r, const toml::table& sys, const toml::node& from,
                                             int base, std::string& type_out, int depth, toml::table* resolved);

// A .json file that is not JSON (its first non-blank byte is not '{'): a scene file named so.
bool tomlNamedJson(const std::string& path);

// The scene a graph, mesh or FOLD file given as SCENE stands for: `[system] from = FILE`.
toml::table importedSceneDocument(const std::string& path);

// scene_catalog.cpp

// [system] type = "catalog": the model of the named entry's system.
std::unique_ptr<engine::Model> buildCatalog(const Reader& r, const toml::table& sys, int outer_base,
                                            std::string& type_out, int depth, toml::table* resolved);

// A catalog entry's title and settings as the defaults of the scene `doc` that names it.
void mergeCatalogEntry(toml::table& doc);

// scene_settings.cpp: [motion], [analysis], [render], [projection] and [[output]], read after
// [system] (scene.model is built).

void readMotion(const Reader& r, const toml::table& t, Scene& scene);
void readAnalysis(const Reader& r, const toml::table& t, Scene& scene);
void readRender(const Reader& r, const toml::table& t, Scene& scene);
void readProjection(const Reader& r, const toml::table& t, Scene& scene);
void readOutputs(const Reader& r, const toml::node& n, std::vector<OutputSpec>& outs);

}  // namespace flexure::scenes::detail
