# Loads each page in headless Chromium over the DevTools protocol (--remote-debugging-pipe: JSON messages,
# NUL-terminated, on fds 3 (to Chromium) and 4 (from it)) and prints every console error: console.error()
# calls, uncaught exceptions, and the browser's own error entries (a resource that fails to load).
# argv: CHROMIUM PAGE... ; exit 0 when no page had one, 1 otherwise, 2 when Chromium could not be driven.
import json, os, shutil, subprocess, sys, tempfile, time

_profiles = []

def main():
    chromium, pages = sys.argv[1], sys.argv[2:]
    to_r, to_w = os.pipe()
    from_r, from_w = os.pipe()
    profile = tempfile.mkdtemp(prefix='mannequin_chromium_')
    _profiles.append(profile)
    # as root Chromium refuses to start without --no-sandbox
    args = [chromium, '--headless', '--no-sandbox', '--disable-gpu', '--remote-debugging-pipe', '--no-first-run',
            '--user-data-dir=' + profile, 'about:blank']
    proc = subprocess.Popen(args, pass_fds=(3, 4), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            preexec_fn=lambda: (os.dup2(to_r, 3), os.dup2(from_w, 4)))
    os.close(to_r); os.close(from_w)
    buf, ident = b'', [0]
    def send(method, params=None, session=None):
        ident[0] += 1
        m = {'id': ident[0], 'method': method, 'params': params or {}}
        if session: m['sessionId'] = session
        os.write(to_w, json.dumps(m).encode() + b'\0')
        return ident[0]
    def receive(deadline):
        nonlocal buf
        while b'\0' not in buf:
            if time.monotonic() > deadline: raise TimeoutError('no answer from Chromium')
            chunk = os.read(from_r, 65536)
            if not chunk: raise EOFError('Chromium closed the pipe')
            buf += chunk
        msg, buf = buf.split(b'\0', 1)
        return json.loads(msg)
    def call(method, params=None, session=None, timeout=30, events=None):
        i, deadline = send(method, params, session), time.monotonic() + timeout
        while True:
            m = receive(deadline)
            if m.get('id') == i:
                if 'error' in m: raise RuntimeError('%s: %s' % (method, m['error']))
                return m.get('result', {})
            if events is not None: events.append(m)
    failures = 0
    try:
        for page in pages:
            url = 'file://' + os.path.abspath(page)
            events = []
            target = call('Target.createTarget', {'url': 'about:blank'})['targetId']
            session = call('Target.attachToTarget', {'targetId': target, 'flatten': True})['sessionId']
            for domain in ('Runtime.enable', 'Log.enable', 'Page.enable'):
                call(domain, session=session, events=events)
            call('Page.navigate', {'url': url}, session=session, events=events)
            deadline = time.monotonic() + 30
            while not any(e.get('method') == 'Page.loadEventFired' and e.get('sessionId') == session for e in events):
                events.append(receive(deadline))
            # what the page logs right after its load event
            call('Runtime.evaluate', {'expression': 'new Promise(r => setTimeout(r, 200))', 'awaitPromise': True},
                 session=session, events=events)
            errors = []
            for e in events:
                if e.get('sessionId') != session: continue
                p = e.get('params', {})
                if e.get('method') == 'Runtime.consoleAPICalled' and p.get('type') in ('error', 'assert'):
                    errors.append('console.%s: %s' % (p['type'], ' '.join(str(a.get('value', a.get('description'))) for a in p.get('args', []))))
                elif e.get('method') == 'Runtime.exceptionThrown':
                    d = p['exceptionDetails']
                    errors.append('exception: %s' % d.get('exception', {}).get('description', d.get('text')))
                elif e.get('method') == 'Log.entryAdded' and p['entry'].get('level') == 'error':
                    errors.append('%s: %s' % (p['entry'].get('source'), p['entry'].get('text')))
            for x in errors: print('%s: %s' % (page, x))
            if not errors: print('%s: no console errors' % page)
            failures += 1 if errors else 0
            call('Target.closeTarget', {'targetId': target})
        try: call('Browser.close', timeout=10)
        except Exception: pass
    except Exception as e:
        print('cannot drive Chromium: %s' % e)
        proc.kill()
        proc.wait()
        return 2
    proc.wait(timeout=30)
    return 1 if failures else 0

def run():
    try:
        return main()
    finally:
        for d in _profiles: shutil.rmtree(d, ignore_errors=True)

sys.exit(run())
