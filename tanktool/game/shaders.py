"""GLSL (OpenGL 3.3 core) of the 3D view.

The scene shader is compiled once per quality level with ``#define``s rather than
branching on uniforms: Mesa's llvmpipe turns each shader into machine code, and code
that is not there costs nothing.

* **scene**: the paper's point light (D3DLIGHT8: position, range, attenuation
  1/(a0 + a1·d + a2·d²)) with Phong shading per pixel (Blinn's half vector), ambient,
  the material's texture, a team tint that keeps the texture's detail, the shadow map
  (hardware 2×2 PCF through ``sampler2DShadow``): one map, the arena's depth drawn once
  with this frame's tanks drawn into it; and distance fog
  towards the horizon's colour;
* **depth**: the shadow pass, positions only;
* **sky**: a grid over the window at the far plane, drawn after the scene so that only
  the pixels no geometry covered are shaded: a gradient from the horizon (the fog's
  colour) to the zenith and a glow around the light's direction, per vertex; with
  ``CLOUDS`` a cloud layer, per pixel;
* **particles**: camera-facing quads instanced from one buffer, round and soft, sized
  in metres but never wider on screen than ``max_screen`` of the window's height and
  faded out close to the camera (an explosion never fills the view);
* **beams**: tracers, ribbons already facing the camera (built on the CPU);
* **flat**: the benchmark's reference: positions only, one colour;
* **hud**: a texture over the window.
"""

from __future__ import annotations

SCENE_VERTEX = """
uniform mat4 mvp;
uniform mat4 model;
uniform mat4 light_vp;        // light view-projection with the [0, 1] bias and the depth offset
uniform vec3 eye;
uniform float fog_k;          // visibility = 1 / (1 + fog_k * distance^2)
uniform vec3 light_pos;
uniform vec3 light_colour;
uniform vec3 attenuation;     // a0, a1, a2 as D3DLIGHT8's Attenuation0..2
uniform float light_range;
in vec3 in_pos;
in vec3 in_normal;
in vec3 in_colour;
in vec2 in_uv;
out vec2 v_uv;
#if PER_PIXEL
out vec3 v_colour;
out float v_visible;          // the fog's visibility
out vec3 v_normal;
out vec3 v_to_light;          // affine in the position: interpolated exactly, normalised per pixel
out vec3 v_to_eye;
out float v_att;
#else
uniform vec3 ambient;
out vec3 v_ambient;           // colour x ambient light x fog visibility
out vec3 v_direct;            // colour x the point light's diffuse light x fog visibility
out float v_fog;              // 1 - visibility: the share of the fog's colour
#endif
#if SHADOWS
out vec4 v_light;
#endif
void main() {
    vec4 world = model * vec4(in_pos, 1.0);
    v_uv = in_uv;
    vec3 to_light = light_pos - world.xyz;
    float d = length(to_light);
    float att = d > light_range ? 0.0 : 1.0 / (attenuation.x + attenuation.y * d + attenuation.z * d * d);
    vec3 to_eye = eye - world.xyz;
    float visible = 1.0 / (1.0 + fog_k * dot(to_eye, to_eye));
#if PER_PIXEL
    v_colour = in_colour;
    v_visible = visible;
    v_normal = mat3(model) * in_normal;
    v_to_light = to_light;
    v_to_eye = to_eye;
    v_att = att;
#else
    vec3 n = normalize(mat3(model) * in_normal);
    vec3 direct = light_colour * (max(dot(n, to_light / d), 0.0) * att);
    v_ambient = in_colour * ambient * visible;
    v_direct = in_colour * direct * visible;
    v_fog = 1.0 - visible;
#endif
#if SHADOWS
    v_light = light_vp * world;
#endif
    gl_Position = mvp * vec4(in_pos, 1.0);
}
"""

# PER_PIXEL 1 is Phong shading: the normal, the direction to the light and the one to
# the eye interpolated and normalised for every pixel, the diffuse term and Blinn's
# specular (its power as five squarings: llvmpipe's pow costs more than the rest of
# the shader) worked out there; only the attenuation and the fog, which change slowly,
# come from the vertices (the arena's big triangles are split for them, game/meshes.py).
# PER_PIXEL 0 lights each vertex (as Direct3D 8's fixed pipeline lit the paper's arena)
# and leaves the pixel its texture and its shadow: the arena at the low and medium
# presets.  There everything that does not change across a triangle -- colour, ambient,
# light, fog -- is folded into three values per vertex, and the pixel does one texture
# and one shadow lookup and two multiply-adds.
#
# ARENA 1 leaves out the tanks' team tint, emission and the "has a texture" switch (an
# untextured batch is given a white texture): llvmpipe runs both sides of an `if` with
# masks, so code a pixel never needs still costs it (a sixth of an arena pixel's time).
#
# One shadow map: the arena's depth from the light, drawn once, with this frame's tanks
# drawn into it (game/shadows.py): one lookup per pixel, not one per map.
SCENE_FRAGMENT = """
uniform vec3 fog_colour;
uniform sampler2D tex;
#if SHADOWS
uniform sampler2DShadow shadow_map;
in vec4 v_light;
#endif
in vec2 v_uv;
out vec4 frag;

float shadowed() {
#if SHADOWS
    return textureProj(shadow_map, v_light);
#else
    return 1.0;
#endif
}

#if PER_PIXEL
uniform vec3 ambient;
uniform vec3 light_colour;
in vec3 v_colour;
in float v_visible;
in vec3 v_normal;
in vec3 v_to_light;
in vec3 v_to_eye;
in float v_att;
#if !ARENA
uniform vec3 tint;
uniform float tint_amount;
uniform float tex_luma;       // the texture's mean luminance: a tint keeps its detail
uniform float use_texture;
uniform vec3 emissive;
uniform float alpha;
#endif

void main() {
#if ARENA
    vec3 base = v_colour * texture(tex, v_uv).rgb;
#else
    vec3 base = v_colour;
    if (use_texture > 0.5) base *= texture(tex, v_uv).rgb;
    if (tint_amount > 0.0) {               // tanks: the team colour, keeping the texture's light and dark
        float luma = dot(base, vec3(0.2126, 0.7152, 0.0722));
        base = mix(base, tint * clamp(luma / tex_luma, 0.35, 1.6), tint_amount);
    }
#endif
    vec3 n = normalize(v_normal);
    vec3 l = normalize(v_to_light);
    float diffuse = max(dot(n, l), 0.0);
    float spec = max(dot(n, normalize(l + normalize(v_to_eye))), 0.0);
    spec *= spec; spec *= spec; spec *= spec; spec *= spec; spec *= spec;      // ^32
    float lit = v_att * shadowed();
    vec3 colour = base * (ambient + light_colour * (diffuse * lit)) + (0.25 * spec * lit) * light_colour;
#if ARENA
    frag = vec4(mix(fog_colour, colour, v_visible), 1.0);
#else
    frag = vec4(mix(fog_colour, colour + emissive, v_visible), alpha);
#endif
}
#else
in vec3 v_ambient;
in vec3 v_direct;
in float v_fog;

void main() {
    vec3 t = texture(tex, v_uv).rgb;
    frag = vec4(t * (v_ambient + v_direct * shadowed()) + fog_colour * v_fog, 1.0);
}
#endif
"""

DEPTH_VERTEX = """
uniform mat4 mvp;
in vec3 in_pos;
void main() { gl_Position = mvp * vec4(in_pos, 1.0); }
"""

DEPTH_FRAGMENT = """
out vec4 frag;
void main() { frag = vec4(1.0); }
"""

# Puts the arena's depth back into the shadow map where last frame's tanks were drawn:
# quads over those texels copy it from a plain float texture of the arena's map (one draw
# call; a texture upload per rectangle costs llvmpipe more than the pixels).
RESTORE_VERTEX = """
in vec2 in_pos;               // the map's clip space
void main() { gl_Position = vec4(in_pos, 0.0, 1.0); }
"""

RESTORE_FRAGMENT = """
uniform sampler2D arena_depth;
void main() { gl_FragDepth = texelFetch(arena_depth, ivec2(gl_FragCoord.xy), 0).r; }
"""

# The sky is a grid over the window at the far plane: its colour (gradient, the light's
# glow) is worked out per vertex and interpolated, so a pixel of sky costs nothing but
# the optional cloud lookup; it is drawn after the scene, only where nothing else is.
SKY_VERTEX = """
uniform mat4 inv_view_proj;
uniform vec3 horizon;
uniform vec3 zenith;
uniform vec3 sun_dir;
uniform vec3 eye;
uniform float time;
in vec2 in_pos;
out vec3 v_colour;
out vec2 v_cloud_uv;
out float v_cloud;
void main() {
    vec4 far = inv_view_proj * vec4(in_pos, 1.0, 1.0);
    vec3 dir = normalize(far.xyz / far.w - eye);
    float up = max(dir.y, 0.0);
    float sun = max(dot(dir, sun_dir), 0.0);
    v_colour = mix(horizon, zenith, pow(up, 0.55)) + vec3(1.0, 0.92, 0.75) * 0.3 * pow(sun, 12.0);
    v_cloud_uv = dir.xz / (max(dir.y, 0.0) + 0.08) * 0.35 + vec2(time * 0.004, time * 0.0015);
    v_cloud = smoothstep(0.02, 0.25, dir.y);     // 0.02: sky.CLOUD_BASE (the rows under it skip the clouds)
    gl_Position = vec4(in_pos, 1.0, 1.0);
}
"""

SKY_FRAGMENT = """
#if CLOUDS
uniform sampler2D clouds;
#endif
in vec3 v_colour;
in vec2 v_cloud_uv;
in float v_cloud;
out vec4 frag;
void main() {
    vec3 colour = v_colour;
#if CLOUDS
    float c = texture(clouds, v_cloud_uv).r;
    float cover = clamp((c - 0.45) * 3.0, 0.0, 1.0) * v_cloud;
    colour = mix(colour, vec3(0.96, 0.97, 1.0) * (0.85 + 0.15 * c), cover * 0.8);
#endif
    frag = vec4(colour, 1.0);
}
"""

PARTICLE_VERTEX = """
uniform mat4 view_proj;
uniform vec3 cam_right;
uniform vec3 cam_up;
uniform vec3 eye;
uniform float max_screen;    // the widest a particle may be: this share of the window's height
uniform float tan_half_fov;
in vec2 in_corner;
in vec4 in_particle;         // x y z size
in vec4 in_rgba;
in float in_glow;            // 1: adds light (fire, sparks), 0: covers (smoke, dust, debris)
out vec2 v_corner;
out vec4 v_rgba;
out float v_glow;
void main() {
    float dist = max(length(in_particle.xyz - eye), 0.01);
    // a particle of size s at distance d covers s / (2 d tan(fov/2)) of the height
    float size = min(in_particle.w, max_screen * 2.0 * dist * tan_half_fov);
    vec3 p = in_particle.xyz + (cam_right * in_corner.x + cam_up * in_corner.y) * size * 0.5;
    v_corner = in_corner;
    // close to the camera a particle fades away rather than covering the view
    v_rgba = vec4(in_rgba.rgb, in_rgba.a * smoothstep(1.5, 7.0, dist));
    v_glow = in_glow;
    gl_Position = view_proj * vec4(p, 1.0);
}
"""

PARTICLE_FRAGMENT = """
in vec2 v_corner;
in vec4 v_rgba;
in float v_glow;
out vec4 frag;
void main() {
    float r2 = dot(v_corner, v_corner);
    if (r2 >= 1.0) discard;
    float a = v_rgba.a * (1.0 - r2) * (1.0 - r2);
    // premultiplied alpha: one blend mode (ONE, ONE_MINUS_SRC_ALPHA) serves glow and smoke
    frag = vec4(v_rgba.rgb * a, a * (1.0 - v_glow));
}
"""

BEAM_VERTEX = """
uniform mat4 view_proj;
in vec3 in_pos;
in vec2 in_across;           // x: -1..1 across the ribbon, y: 0 tail .. 1 head
in vec4 in_rgba;
out vec2 v_across;
out vec4 v_rgba;
void main() { v_across = in_across; v_rgba = in_rgba; gl_Position = view_proj * vec4(in_pos, 1.0); }
"""

BEAM_FRAGMENT = """
in vec2 v_across;
in vec4 v_rgba;
out vec4 frag;
void main() {
    float a = v_rgba.a * (1.0 - v_across.x * v_across.x) * v_across.y;
    frag = vec4(v_rgba.rgb * a, 0.0);   // light only: added to what is behind
}
"""

FLAT_VERTEX = DEPTH_VERTEX

FLAT_FRAGMENT = """
uniform vec3 colour;
out vec4 frag;
void main() { frag = vec4(colour, 1.0); }
"""

HUD_VERTEX = """
#version 330 core
in vec2 in_pos;
out vec2 uv;
void main() { uv = vec2(in_pos.x * 0.5 + 0.5, 0.5 - in_pos.y * 0.5); gl_Position = vec4(in_pos, 0.0, 1.0); }
"""

HUD_FRAGMENT = """
#version 330 core
uniform sampler2D hud;
in vec2 uv;
out vec4 frag;
void main() { frag = texture(hud, uv); }
"""


def source(body: str, **defines: int) -> str:
    """A shader of ``body`` with ``#version 330 core`` and ``#define NAME value`` lines."""
    # every switch a shader tests with #if is defined (0 unless given): GLSL has no default
    defines = {"SHADOWS": 0, "PER_PIXEL": 1, "ARENA": 0, "CLOUDS": 0, **defines}
    head = "#version 330 core\n" + "".join(f"#define {k} {int(v)}\n" for k, v in sorted(defines.items()))
    return head + body
