import { defineConfig } from 'vite';

// The C++ server (`specdeform edit`) serves dist/; assets use relative paths.
export default defineConfig({
  base: './',
  build: { outDir: 'dist', emptyOutDir: true, chunkSizeWarningLimit: 1024 },
});
