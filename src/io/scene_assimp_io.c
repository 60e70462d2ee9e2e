// assimp's file access for drift (scene_io_internal.h, drift__assimp_import_file).
//
// assimp opens an OBJ's mtllib and a glTF's buffers itself, with fopen: a FIFO named there
// blocked the load forever, and drift never learnt of those files (so --stats could name the
// scene's .mtl and overwrite it). Here every open goes through drift_input_open and each
// side file is reported to on_input, like the textures drift loads itself.
#include "drift/file.h"
#include "scene_io_internal.h"

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/scene.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

typedef struct assimp_io {
    const char *path; // the mesh file (already reported by the caller)
    drift_scene_input_fn on_input;
    void *user;
    char refused[4096]; // the first side file that is not a regular file, and why
    char why[128];
} assimp_io;

static FILE *file_of(struct aiFile *f)
{
    return (FILE *)(void *)f->UserData;
}

static size_t io_read(struct aiFile *f, char *buffer, size_t size, size_t count)
{
    return fread(buffer, size, count, file_of(f));
}

static size_t io_write(struct aiFile *f, const char *buffer, size_t size, size_t count)
{
    (void)f;
    (void)buffer;
    (void)size;
    (void)count;
    return 0; // inputs only
}

static size_t io_tell(struct aiFile *f)
{
    long at = ftell(file_of(f));
    return at < 0 ? 0 : (size_t)at;
}

static size_t io_size(struct aiFile *f)
{
    struct stat st;
    return fstat(fileno(file_of(f)), &st) == 0 ? (size_t)st.st_size : 0;
}

static enum aiReturn io_seek(struct aiFile *f, size_t offset, enum aiOrigin origin)
{
    int whence = origin == aiOrigin_SET ? SEEK_SET : origin == aiOrigin_CUR ? SEEK_CUR : SEEK_END;
    if (offset > (size_t)0x7fffffffffffffffull) {
        return aiReturn_FAILURE;
    }
    return fseek(file_of(f), (long)offset, whence) == 0 ? aiReturn_SUCCESS : aiReturn_FAILURE;
}

static void io_flush(struct aiFile *f)
{
    (void)f;
}

static struct aiFile *io_open(struct aiFileIO *io, const char *path, const char *mode)
{
    assimp_io *s = (assimp_io *)(void *)io->UserData;
    if (!path || !mode || strchr(mode, 'w') || strchr(mode, 'a') || strchr(mode, '+')) {
        return NULL;
    }
    char why[128];
    FILE *file = drift_input_fopen(path, why, sizeof why);
    if (!file) {
        // A missing file is assimp's to judge (it probes for optional ones); a FIFO or a
        // device is an error of the scene.
        if (errno == EINVAL && !s->refused[0]) {
            snprintf(s->refused, sizeof s->refused, "%s", path);
            snprintf(s->why, sizeof s->why, "%s", why);
        }
        return NULL;
    }
    struct aiFile *f = calloc(1, sizeof *f);
    if (!f) {
        fclose(file);
        return NULL;
    }
    f->ReadProc = io_read;
    f->WriteProc = io_write;
    f->TellProc = io_tell;
    f->FileSizeProc = io_size;
    f->SeekProc = io_seek;
    f->FlushProc = io_flush;
    f->UserData = (aiUserData)(void *)file;
    if (s->on_input && strcmp(path, s->path) != 0) {
        s->on_input(path, s->user);
    }
    return f;
}

static void io_close(struct aiFileIO *io, struct aiFile *f)
{
    (void)io;
    if (f) {
        fclose(file_of(f));
        free(f);
    }
}

drift_result drift__assimp_import_file(drift_context *ctx, const char *path, unsigned flags,
                                       const char *where, int line, drift_scene_input_fn on_input,
                                       void *user, const struct aiScene **out_ai)
{
    assimp_io state = { .path = path, .on_input = on_input, .user = user };
    struct aiFileIO io = { .OpenProc = io_open,
                           .CloseProc = io_close,
                           .UserData = (aiUserData)(void *)&state };
    const struct aiScene *ai = aiImportFileEx(path, flags, &io);
    if (state.refused[0]) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, where, line, "'%s' (read by '%s'): %s",
                  state.refused, path, state.why);
        aiReleaseImport(ai);
        ai = NULL;
    }
    *out_ai = ai;
    return state.refused[0] ? DRIFT_ERR_IO : DRIFT_OK;
}
