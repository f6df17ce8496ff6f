/* The viewer's page and scripts, in the plugin library (nothing is read from disk or the network
   when it runs): its own files, and three.js with its orbit controls from Debian's libjs-three,
   paths given by CMake. */
#define STR2(x) #x
#define STR(x) STR2(x)
#define ASSET(name, file)      \
  .global name;                \
  .type name, @object;         \
  .balign 16;                  \
  name:                        \
  .incbin STR(file);           \
  .global name##_end;          \
  name##_end:                  \
  .byte 0

  .section .rodata
  ASSET(ssx_viewer_index_html, SSX_VIEWER_INDEX)
  ASSET(ssx_viewer_js, SSX_VIEWER_JS)
  ASSET(ssx_viewer_three_js, SSX_VIEWER_THREE)
  ASSET(ssx_viewer_orbit_js, SSX_VIEWER_ORBIT)
  .section .note.GNU-stack,"",@progbits
