/* placeholder so the library has a source until samples.c lands */
typedef int sw_samples_placeholder;
