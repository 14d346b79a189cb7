// The file formats users already have, read into what a scene's [system] table holds: graphs
// from nauty's graph6 and sparse6 (B. McKay's "Description of graph6, sparse6 and digraph6
// encodings"), and polyhedral surfaces from OFF, OBJ and STL meshes. Every problem is a
// SceneError at the file, line and column (binary STL: the byte offset as the column).
#pragma once

#include <array>
#include <string>
#include <vector>

namespace flexure::scenes {

// The most vertices and edges an imported graph or mesh may have (memory: the scene's tables
// hold them too).
constexpr long long kMaxImportedVertices = 2'000'000;
constexpr long long kMaxImportedEdges = 5'000'000;
// Vertices on no edge that a sparse6 line may declare (its header names any count).
constexpr long long kMaxIsolatedVertices = 100'000;

struct ImportedGraph {
  int vertices = 0;
  std::vector<std::array<int, 2>> edges;  // 0-based, i < j, each once
  std::vector<std::vector<double>> positions;  // a realization the file gives (node-link "pos"), or empty
};

// Every graph of a graph6/sparse6 text: one per line, with or without the >>graph6<< or
// >>sparse6<< header; empty lines are skipped. Loops and repeated edges (sparse6 multigraphs)
// are refused: a bar joins two vertices, once.
std::vector<ImportedGraph> readGraph6(const std::string& text, const std::string& file);
// Only the `which`-th graph (from 1) is decoded; `count` is how many the file holds (an empty
// graph comes back when which is beyond it).
ImportedGraph readGraph6(const std::string& text, const std::string& file, long long which, long long& count);

// An edge list (networkx's write_edgelist, and most tools'): one edge per line, its two vertex
// labels first (separated by blanks or a comma; anything after them, such as a weight, is
// ignored); # starts a comment. Vertices are numbered in the order of their labels: by value
// when every label is an integer, else by first appearance. Loops and repeated edges are refused.
ImportedGraph readEdgeList(const std::string& text, const std::string& file);
// networkx's node-link JSON (node_link_data): "nodes" [{"id": ...}, ...] and "links" (or
// "edges") [{"source": ..., "target": ...}, ...]; "pos" on every node (2 or 3 numbers) is the
// realization. Vertices are numbered in the order of "nodes". Errors name the array and index
// (links[3].target), or the line and column of a JSON syntax error.
ImportedGraph readNodeLink(const std::string& text, const std::string& file);

struct ImportedMesh {
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::vector<int>> faces;  // 0-based cyclic vertex lists
};

// OFF ("OFF", counts, vertices, faces as "k i1 ... ik"; # comments).
ImportedMesh readOff(const std::string& text, const std::string& file);
// OBJ ("v x y z", "f a b c ..." with a, a/t, a/t/n or a//n, 1-based or negative; other records
// are ignored).
ImportedMesh readObj(const std::string& text, const std::string& file);
// STL, ASCII or binary: its triangles welded at equal points (within 1e-9 of the mesh's
// extent) and edge-adjacent coplanar triangles merged into one planar facet each (its boundary
// must be one loop).
ImportedMesh readStl(const std::string& bytes, const std::string& file);

// Whether a file name's extension is one `from` (and the command line) reads: g6, s6, graph6,
// sparse6, edges, edgelist, json (node-link), off, obj, stl (any case).
bool isImportable(const std::string& file);
// graph6/sparse6: a stream of graphs (what a sweep reads one by one).
bool isGraphFile(const std::string& file);
// One graph: an edge list or node-link JSON.
bool isEdgeListFile(const std::string& file);
bool isNodeLinkFile(const std::string& file);

}  // namespace flexure::scenes
