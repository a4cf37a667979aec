// Procedural sky shared by the sky pass and the fog of the scene pass, so the horizon and the
// distant terrain fade into the same colour.
vec3 sky_radiance(vec3 direction, vec3 sun_direction, float sun_intensity) {
  float up = clamp(direction.y, -1.0, 1.0);
  vec3 zenith = vec3(0.18, 0.36, 0.78);
  vec3 horizon = vec3(0.70, 0.80, 0.92);
  vec3 ground = vec3(0.32, 0.30, 0.27);
  // Square roots and products, not pow: the water evaluates this for every pixel it reflects.
  vec3 sky = mix(horizon, up >= 0.0 ? zenith : ground, sqrt(abs(up)));
  float sun = max(dot(direction, sun_direction), 0.0);
  float sun_2 = sun * sun;
  float sun_4 = sun_2 * sun_2;
  sky += vec3(1.0, 0.85, 0.6) * (sun_4 * sun_4 * 0.25);                    // glow around the sun
  sky += vec3(1.0, 0.95, 0.85) * (smoothstep(0.9995, 0.9998, sun) * sun_intensity);  // disc
  return sky;
}
