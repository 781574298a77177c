// Uniforms the framework sets for the geometry pass (gbuffer.vert / gbuffer.frag).
#include "gbuffer_layout.h"

uniform mat4 u_model;              // object -> world
uniform mat3 u_normal_matrix;      // transpose(inverse(mat3(u_model)))

#include "camera_uniforms.glsl"
#include "material_uniforms.glsl"
