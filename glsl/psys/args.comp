#version 450
// One invocation. mode 0 (before the update): the update's indirect dispatch over the
// alive list it reads, and the other list emptied. mode 1 (after): the draw's instance
// vertex count from the list the update wrote. mode 3: the spawn's dispatch over the
// events the update recorded.
#include "common/index.glsl"
#include "state.glsl"
void main() {
    if (pc.mode == 0u) {
        uint total = (c.alive[pc.cur] + 255u) / 256u;  // update.comp's workgroup size
        c.update_args[0] = min(total, 65535u);
        c.update_args[1] = total == 0u ? 1u : (total + 65534u) / 65535u;
        c.update_args[2] = 1u;
        c.alive[1u - pc.cur] = 0u;
        ev_count = 0u;
    } else if (pc.mode == 1u) {
        c.draw_args[0] = c.verts * c.alive[1u - pc.cur];
    } else if (pc.mode == 2u) {
        c.draw_args[0] = 0u;
    } else {
        uint total = (min(ev_count, uint(ev.length())) + 255u) / 256u;  // emit.comp's size
        ev_args[0] = min(total, 65535u);
        ev_args[1] = total == 0u ? 1u : (total + 65534u) / 65535u;
        ev_args[2] = 1u;
    }
}
