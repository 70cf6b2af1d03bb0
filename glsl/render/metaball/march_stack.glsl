// The path stack of glass and tinted (march.comp): STACK (1..8) named slots, pushed and
// popped through branches on the stack pointer, so a GPU compiler keeps them in registers.
#ifndef RENDER_METABALL_MARCH_STACK_GLSL
#define RENDER_METABALL_MARCH_STACK_GLSL
#if !defined(STACK) || STACK < 1 || STACK > 8
#error "STACK is the path stack's slots, 1..8 (the recursion depth + 1)"
#endif
Path s0, s1, s2, s3, s4, s5, s6, s7;
int sp = 0;

void push(Path p) {
    switch (sp) {
    case 0: s0 = p; break;
#if STACK > 1
    case 1: s1 = p; break;
#endif
#if STACK > 2
    case 2: s2 = p; break;
#endif
#if STACK > 3
    case 3: s3 = p; break;
#endif
#if STACK > 4
    case 4: s4 = p; break;
#endif
#if STACK > 5
    case 5: s5 = p; break;
#endif
#if STACK > 6
    case 6: s6 = p; break;
#endif
#if STACK > 7
    case 7: s7 = p; break;
#endif
    default: break;
    }
    sp++;
}

Path pop() {
    sp--;
    switch (sp) {
#if STACK > 1
    case 1: return s1;
#endif
#if STACK > 2
    case 2: return s2;
#endif
#if STACK > 3
    case 3: return s3;
#endif
#if STACK > 4
    case 4: return s4;
#endif
#if STACK > 5
    case 5: return s5;
#endif
#if STACK > 6
    case 6: return s6;
#endif
#if STACK > 7
    case 7: return s7;
#endif
    default: return s0;
    }
}
#endif
