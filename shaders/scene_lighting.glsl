// Lighting and fog of everything the scene pass draws (terrain, riverbed, objects), so objects
// from glTF files sit in the same light and haze as the valley. Evaluated per vertex: both vary
// slowly over the 1.5 m terrain grid, and per fragment they were a third of the scene pass (a
// glTF mesh of large triangles gets its fog and sun interpolated linearly across each).
#include "sky_common.glsl"

// A vertex's light, in the form that shades a fragment in one multiply-add (shade_scene): fewer
// values to interpolate, which a software rasterizer pays for per triangle and per pixel.
struct SceneLight {
  vec3 lit;   // sun (Lambert) and hemispheric sky light less the fog's share: times the albedo
  vec3 haze;  // the sky colour of the view direction times the fog's share (0 clear .. 1 sky)
};

SceneLight light_scene(SceneConstants scene, float occlusion, vec3 world, vec3 normal) {
  vec3 n = normalize(normal);
  vec3 sun = scene.sun_direction.xyz;
  // Sun (Lambert) plus a hemispheric sky term scaled by ambient occlusion.
  float diffuse = max(dot(n, sun), 0.0);
  vec3 sky_light = mix(vec3(0.20, 0.19, 0.17), vec3(0.35, 0.45, 0.62), n.y * 0.5 + 0.5);
  vec3 irradiance = vec3(1.0, 0.95, 0.85) * 1.1 * diffuse + sky_light * occlusion;
  // Height-attenuated exponential fog towards the sky colour of the view direction.
  vec3 to_vertex = world - scene.camera_position.xyz;
  float dist = length(to_vertex);
  vec3 direction = to_vertex / max(dist, 1e-4);
  float density = scene.fog.x * exp(-scene.fog.y * max(world.y + scene.fog.z, 0.0));
  float fog = clamp(1.0 - exp(-density * dist), 0.0, 1.0);
  SceneLight light;
  light.lit = irradiance * (1.0 - fog);
  light.haze = sky_radiance(direction, sun, 0.0) * fog;
  return light;
}

// The albedo lit and fogged: mix(albedo * irradiance, sky, fog).
vec3 shade_scene(vec3 albedo, vec3 lit, vec3 haze) { return albedo * lit + haze; }
