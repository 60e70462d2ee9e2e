// drift render's checkpoints and staged outputs (issue 18, docs/reliability.md).
//
// A checkpoint is every tile's state (the path tracer's sums and sample counts, pt.h) and
// the key of the render it belongs to: drift's version, the scene's content, the image
// size, the seed and the depth. Resuming loads the tiles and renders on; since a pixel's
// samples are summed in index order whoever renders them, the end image is the same bits
// as an uninterrupted render's. The file:
//   "drift checkpoint 1\n", key lines "name value\n", "\n",
//   uint32 tile count, each tile's state (drift_pt_tile_get_state), uint64 FNV-1a of all
//   the bytes before it (a cut or damaged file is refused, not half loaded).
#include "drift/file.h"
#include "drift/pt.h"
#include "render.h"

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef DRIFT_VERSION
#    define DRIFT_VERSION "unknown"
#endif
#ifndef DRIFT_COMMIT
#    define DRIFT_COMMIT "unknown"
#endif

static const char checkpoint_magic[] = "drift checkpoint 1\n";

void render_checkpoint_path(const char *exr_path, char *out, size_t size)
{
    snprintf(out, size, "%.*s.ckpt", (int)(strlen(exr_path) - 4), exr_path);
}

bool render_checkpoint_key(const cli_session *session, const drift_pt *pt, const char *edits_path,
                           char *key, size_t size)
{
    uint64_t scene = 0, edits = 0;
    if (!cli_hash_files((const char *const *)session->scene_inputs, session->scene_input_count,
                        &scene) ||
        !cli_hash_files(&edits_path, 1, &edits)) {
        fprintf(stderr, "drift render: cannot read the scene's files for the checkpoint: %s\n",
                strerror(errno));
        return false;
    }
    drift_pt_params p = drift_pt_get_params(pt);
    snprintf(key, size,
             "drift %s\nscene-content %016llx\nreflection-edits %016llx\nsize %dx%d\nseed "
             "%u\nmax-depth %d\n"
             "tile-size %d\n",
             DRIFT_VERSION " " DRIFT_COMMIT, (unsigned long long)scene, (unsigned long long)edits,
             p.width, p.height, p.seed, p.max_depth, DRIFT_PT_TILE_SIZE);
    return true;
}

bool render_checkpoint_write(const char *path, const char *key, const drift_pt *pt)
{
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp-%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    bool ok = f != NULL;
    uint64_t h = CLI_FNV_BASIS;
    uint8_t *state = NULL;
    uint32_t tiles = drift_pt_tile_count(pt);
    if (ok) {
        h = cli_fnv1a(h, checkpoint_magic, strlen(checkpoint_magic));
        h = cli_fnv1a(h, key, strlen(key));
        h = cli_fnv1a(h, "\n", 1);
        h = cli_fnv1a(h, &tiles, sizeof tiles);
        ok = fputs(checkpoint_magic, f) >= 0 && fputs(key, f) >= 0 && fputc('\n', f) != EOF &&
             fwrite(&tiles, sizeof tiles, 1, f) == 1;
        state = malloc(drift_pt_tile_state_size(pt, 0));
        ok = ok && state;
    }
    for (uint32_t t = 0; ok && t < tiles; ++t) {
        size_t n = drift_pt_tile_state_size(pt, t);
        drift_pt_tile_get_state(pt, t, state);
        h = cli_fnv1a(h, state, n);
        ok = fwrite(state, 1, n, f) == n;
    }
    free(state);
    ok = ok && fwrite(&h, sizeof h, 1, f) == 1 && fflush(f) == 0 && fsync(fileno(f)) == 0;
    int error = errno;
    if (f && fclose(f) != 0 && ok) {
        ok = false;
        error = errno;
    }
    if (ok && rename(tmp, path) != 0) {
        ok = false;
        error = errno;
    }
    if (!ok) {
        remove(tmp);
        fprintf(stderr, "drift render: cannot write the checkpoint %s: %s\n", path,
                strerror(error));
    }
    return ok;
}

// The first line of `want` that `have` lacks, as "name: its A, this run's B".
static void key_difference(const char *have, const char *want, char *out, size_t size)
{
    snprintf(out, size, "its header differs");
    for (const char *line = want; *line;) {
        const char *end = strchr(line, '\n');
        size_t len = end ? (size_t)(end - line) + 1 : strlen(line);
        const char *space = memchr(line, ' ', len);
        size_t name_len = space ? (size_t)(space - line) + 1 : len;
        const char *found = NULL;
        for (const char *h = have; *h;) {
            const char *hend = strchr(h, '\n');
            size_t hlen = hend ? (size_t)(hend - h) + 1 : strlen(h);
            if (hlen == len && memcmp(h, line, len) == 0) {
                found = h;
            }
            if (!found && hlen >= name_len && memcmp(h, line, name_len) == 0) {
                snprintf(out, size, "its %.*s is %.*s, this run's %.*s", (int)name_len - 1, line,
                         (int)(hlen - name_len - 1), h + name_len, (int)(len - name_len - 1),
                         line + name_len);
                return;
            }
            h += hlen;
        }
        if (!found) {
            snprintf(out, size, "it has no '%.*s' line", (int)name_len - 1, line);
            return;
        }
        line += len;
    }
}

int render_checkpoint_read(const char *path, const char *key, drift_pt *pt, uint32_t spp)
{
    char reason[128];
    FILE *f = drift_input_fopen(path, reason, sizeof reason);
    if (!f) {
        fprintf(stderr, "drift render: cannot read the checkpoint %s: %s\n", path, reason);
        return 2;
    }
    uint8_t *data = NULL;
    size_t size = 0, cap = 0;
    for (;;) {
        if (size == cap) {
            cap = cap ? cap * 2 : 1 << 16;
            uint8_t *grown = realloc(data, cap);
            if (!grown) {
                break;
            }
            data = grown;
        }
        size_t n = fread(data + size, 1, cap - size, f);
        size += n;
        if (n == 0) {
            break;
        }
    }
    fclose(f);
    int status = 2;
    size_t magic = strlen(checkpoint_magic);
    const char *why = "not a drift checkpoint";
    char difference[512];
    uint8_t *header_end = NULL;
    if (data && size >= magic && memcmp(data, checkpoint_magic, magic) == 0) {
        why = "cut short or damaged";
        for (size_t i = magic; i + 1 < size && !header_end; ++i) {
            if (data[i] == '\n' && data[i + 1] == '\n') {
                header_end = data + i + 2;
            }
        }
    }
    if (header_end) {
        size_t key_len = (size_t)(header_end - 1 - data) - magic;
        char have[2048];
        snprintf(have, sizeof have, "%.*s", (int)(key_len < 2047 ? key_len : 2047),
                 (const char *)data + magic);
        uint32_t tiles = 0;
        size_t at = (size_t)(header_end - data);
        uint64_t h = 0;
        if (strcmp(have, key) != 0) {
            key_difference(have, key, difference, sizeof difference);
            fprintf(stderr,
                    "drift render: the checkpoint %s is of another render (%s); refusing to "
                    "resume: delete it or render to another --out\n",
                    path, difference);
            free(data);
            return 2;
        }
        size_t body = 0;
        if (at + sizeof tiles <= size) {
            memcpy(&tiles, data + at, sizeof tiles);
        }
        if (tiles == drift_pt_tile_count(pt)) {
            for (uint32_t t = 0; t < tiles; ++t) {
                body += drift_pt_tile_state_size(pt, t);
            }
        }
        if (body && at + sizeof tiles + body + sizeof h == size) {
            memcpy(&h, data + size - sizeof h, sizeof h);
            if (cli_fnv1a(CLI_FNV_BASIS, data, size - sizeof h) == h) {
                uint32_t most = 0;
                const uint8_t *state = data + at + sizeof tiles;
                for (uint32_t t = 0; t < tiles; ++t) {
                    drift_pt_tile_set_state(pt, t, state);
                    state += drift_pt_tile_state_size(pt, t);
                    uint32_t n = drift_pt_tile_sample_count(pt, t);
                    most = n > most ? n : most;
                }
                if (most > spp) {
                    fprintf(stderr,
                            "drift render: the checkpoint %s holds %u spp, more than --spp "
                            "%u; refusing to resume\n",
                            path, most, spp);
                } else {
                    status = 0;
                }
                free(data);
                return status;
            }
        }
    }
    fprintf(stderr, "drift render: the checkpoint %s is %s; refusing to resume\n", path, why);
    free(data);
    return status;
}

// --- STAGED OUTPUTS ---

// Removes what a killed run left beside `path`: "<name>.stage-PID" (and the writers' own
// "<name>.stage-PID.tmp-..." inside it) whose process PID is gone. SIGKILL leaves them, as
// no handler runs; a live PID is another run writing now and is left alone.
static void sweep_stale_stage(const char *path)
{
    const char *slash = strrchr(path, '/');
    char dir[4096];
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) + (slash == path) : 1,
             slash ? path : ".");
    const char *name = slash ? slash + 1 : path;
    size_t name_len = strlen(name);
    DIR *d = opendir(dir);
    if (!d) {
        return;
    }
    for (struct dirent *e; (e = readdir(d)) != NULL;) {
        if (strncmp(e->d_name, name, name_len) != 0 ||
            strncmp(e->d_name + name_len, ".stage-", 7) != 0) {
            continue;
        }
        char *end = NULL;
        long pid = strtol(e->d_name + name_len + 7, &end, 10);
        if (end == e->d_name + name_len + 7 || pid <= 0 || (*end != '\0' && *end != '.') ||
            pid == (long)getpid() || kill((pid_t)pid, 0) == 0 || errno != ESRCH) {
            continue;
        }
        char stale[8192];
        snprintf(stale, sizeof stale, "%s/%s", dir, e->d_name);
        if (unlink(stale) == 0) {
            fprintf(stderr, "drift render: removed %s, left by a run that was killed\n", stale);
        }
    }
    closedir(d);
}

const char *render_stage_add(render_stage *s, const char *path)
{
    if (!path || s->count == sizeof s->files / sizeof s->files[0]) {
        return path;
    }
    sweep_stale_stage(path);
    render_staged_file *f = &s->files[s->count++];
    snprintf(f->path, sizeof f->path, "%s", path);
    snprintf(f->temp, sizeof f->temp, "%s.stage-%ld", path, (long)getpid());
    return f->temp;
}

bool render_stage_commit(render_stage *s)
{
    for (size_t i = 0; i < s->count; ++i) {
        if (rename(s->files[i].temp, s->files[i].path) != 0) {
            fprintf(stderr, "drift render: cannot rename %s to %s: %s\n", s->files[i].temp,
                    s->files[i].path, strerror(errno));
            render_stage_abort(s);
            return false;
        }
        s->files[i].temp[0] = '\0';
    }
    s->count = 0;
    return true;
}

void render_stage_abort(render_stage *s)
{
    for (size_t i = 0; i < s->count; ++i) {
        if (s->files[i].temp[0]) {
            unlink(s->files[i].temp);
        }
    }
    s->count = 0;
}
