// Deterministic procedural textures for the hallway scenes: plaster walls with doors, posters,
// notice boards, radiators and marks; tiled floors; suspended ceilings with lights and vents;
// and "plain" low-texture variants as a deliberately hard case for the VO.
//
// Every texture is built from a seed with the generator's own integer PRNG (splitmix64) and
// hashed value noise, OpenCV's integer drawing functions and order-fixed arithmetic, never
// from <random> distributions: the same (kind, size, options, seed) gives byte-identical
// pixels on every run. The layout is non-periodic by construction (random spacing of doors
// and objects, a shade, noise and wear of its own for every floor tile and ceiling panel), so
// that no repetitive pattern can fool a matcher.
//
// Texture frame: a surface of width_m x height_m metres becomes an image of
// round(width_m * px_per_m) columns x round(height_m * px_per_m) rows. Column 0 is the surface's
// left edge as seen from inside the room, row 0 its top: for walls the ceiling side, for floor
// and ceiling the surface's +y side (the row index grows along -y).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

namespace sim {

// What a texture shows.
enum class TextureKind {
  kWall,          // plaster, skirting, doors, posters, boards, pictures, radiators, signs, marks
  kFloor,         // tiles with grout, each tile its own shade, noise, wear; scuffs and plates
  kCeiling,       // suspended panels on a T-bar grid, lights at irregular cells, vents, sprinklers
  kPlainWall,     // nearly uniform plaster, skirting, a door every ~plain_door_spacing_m
  kPlainFloor,    // nearly uniform seamless floor with a very few faint marks
  kPlainCeiling,  // nearly uniform plaster ceiling with a light every few metres
};

// Parses "wall", "floor", "ceiling", "plainwall", "plainfloor", "plainceiling" (exact,
// lower case); false if unknown, *kind untouched.
bool ParseTextureKind(const std::string& name, TextureKind* kind);
// The name ParseTextureKind() accepts for `kind` ("wall", ..., "plainceiling").
const char* TextureKindName(TextureKind kind);
// True for kPlainWall, kPlainFloor, kPlainCeiling.
bool IsPlainTexture(TextureKind kind);

struct TextureOptions;

// Surface styles a texture name may add to its kind (scenes/README.md, "Textures"): the name of
// a generated texture is "KIND[-STYLE...]_REST", KIND one of ParseTextureKind()'s names:
//   busy       rich kinds: three times the objects and marks (detail_density 3)
//   bare       rich kinds: no objects or marks (detail_density 0): plaster, tiles, panels only
//   posters    rich walls: posters are 90 % of the eye-height objects, 1.5 times as many
//   furniture  walls: no doors, no skirting (the sides of a cabinet, a desk, a pillar)
// A name without styles ("wall_south") gives the kind with default options, as before styles.
// Returns false (kind and options untouched) when the part before the first '_' is not
// KIND[-STYLE...] with known names; *options gets the styles applied over its current values.
bool ParseTextureName(const std::string& texture_name, TextureKind* kind, TextureOptions* options);

struct TextureOptions {
  double px_per_m = 256.0;       // texture resolution (texels per metre), > 0
  double grain_amplitude = 5.0;  // rich kinds: peak of the per-texel grain (grey levels), >= 0
  double shading_amplitude =
      12.0;                     // rich kinds: peak of the low-frequency shading (grey levels), >= 0
  double detail_density = 1.0;  // rich kinds: multiplier on the number of objects and marks
                                // (1 = default hallway, 0 = bare plaster/tiles/panels), >= 0
  double door_gap_min_m =
      1.2;  // rich walls: least wall length between two door frames (metres), > 0
  double door_gap_max_m = 5.0;          // rich walls: largest wall length between two door frames
                                        // (metres), >= door_gap_min_m
  double plain_door_spacing_m = 6.0;    // plain walls: mean distance between door centres
                                        // (metres), > 0; each spacing varies by +-15 %
  double skirting_height_m = 0.1;       // height of the dark skirting strip on walls (metres), >= 0
  double floor_tile_m = 0.5;            // floor tile edge length (metres), > grout_width_m
  double grout_width_m = 0.005;         // grout line width between floor tiles (metres), >= 0;
                                        // drawn at least one texel wide
  double ceiling_panel_m = 0.6;         // suspended-ceiling panel edge length (metres),
                                        // > ceiling_grid_width_m
  double ceiling_grid_width_m = 0.024;  // width of the ceiling's T-bar grid (metres), >= 0;
                                        // drawn at least one texel wide
  double plain_shading_amplitude =
      2.0;  // plain kinds: peak low-frequency shading (grey levels), >= 0
  double plain_grain_amplitude = 0.8;  // plain kinds: peak per-texel grain (grey levels), >= 0
  bool tinted = true;  // true: slightly coloured surfaces and objects; false: B = G = R everywhere
  bool doors = true;   // walls: door frames painted (false: none, as on furniture)
  double poster_share = 0.3;  // rich walls: share of the eye-height objects that are posters
                              // (the rest: boards, pictures, whiteboards, signs, ...), [0, 1)

  // True when every field is finite and in range; otherwise fills *error (may be null).
  bool IsValid(std::string* error) const;
};

// Largest texture side GenerateTexture() produces (texels); larger requests give an empty Mat.
constexpr int kMaxTextureSidePx = 32768;

// Size in texels of the texture of a width_m x height_m surface:
// (round(width_m * px_per_m), round(height_m * px_per_m)); a side that is not finite, negative
// or beyond 4 * kMaxTextureSidePx comes back as 0.
cv::Size TextureSizePx(double width_m, double height_m, const TextureOptions& options = {});

// Returns an 8-bit 3-channel (CV_8UC3, BGR; grey or slightly tinted) image of
// TextureSizePx(width_m, height_m, options) texels covering a surface width_m wide and
// height_m tall (texture frame in the file comment). Fully deterministic: the same
// (kind, width_m, height_m, seed, options) gives byte-identical pixels on any run.
// Returns an empty Mat when options are invalid (see TextureOptions::IsValid), a size is not
// finite, or a side would be < 1 or > kMaxTextureSidePx texels.
cv::Mat GenerateTexture(TextureKind kind, double width_m, double height_m, uint64_t seed,
                        const TextureOptions& options = {});

}  // namespace sim
