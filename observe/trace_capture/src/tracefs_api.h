#pragma once
/* The part of libtracefs (1.6) the kernel recorder calls. <tracefs.h> does not compile as
 * C++: it has no extern "C", and one of its inline functions passes 0 for an enum. So the C++
 * sources include this instead, and tracefs_api_check.c includes both: the C compiler rejects
 * any declaration here that differs from the library's own ("conflicting types"). */

#include <event-parse.h> /* libtraceevent: C++-clean, the tep_* types and calls */
#include <sched.h>
#include <stddef.h>
#ifndef __cplusplus
#include <stdbool.h>
#endif

#ifdef __cplusplus
extern "C" {
#endif

struct tracefs_instance;

const char* tracefs_tracing_dir(void);

bool tracefs_instance_exists(const char* name);
struct tracefs_instance* tracefs_instance_create(const char* name);
int tracefs_instance_destroy(struct tracefs_instance* instance);
void tracefs_instance_free(struct tracefs_instance* instance);

int tracefs_instance_file_write(struct tracefs_instance* instance, const char* file,
                                const char* str);
char* tracefs_instance_file_read(struct tracefs_instance* instance, const char* file, int* psize);
int tracefs_instance_set_affinity(struct tracefs_instance* instance, const char* cpu_str);
int tracefs_instance_set_buffer_size(struct tracefs_instance* instance, size_t size, int cpu);

int tracefs_trace_on(struct tracefs_instance* instance);
int tracefs_trace_off(struct tracefs_instance* instance);

bool tracefs_event_file_exists(struct tracefs_instance* instance, const char* system,
                               const char* event, const char* file);
int tracefs_event_enable(struct tracefs_instance* instance, const char* system, const char* event);

struct tep_handle* tracefs_local_events_system(const char* tracing_dir,
                                               const char* const* sys_names);
int tracefs_iterate_raw_events(struct tep_handle* tep, struct tracefs_instance* instance,
                               cpu_set_t* cpus, int cpu_size,
                               int (*callback)(struct tep_event*, struct tep_record*, int, void*),
                               void* callback_context);

#ifdef __cplusplus
}
#endif
