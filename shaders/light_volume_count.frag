#version 330 core
// Writes nothing: the framework draws with it inside an occlusion query to count the
// fragments a pass reaches its fragment shader with (lab 7's work check,
// common/render/light_volumes.h). Its colour writes are masked off.
out vec4 out_color;

void main() { out_color = vec4(0.0); }
